"""Device clock (kiosk mode): the server plays audio on a local output and broadcasts
that device's sample clock, so several displays agree with each other and the speaker.

The device clock is one continuous sample counter for the life of the server. An
utterance starts at a known device sample (sent in its ``start`` message); a ``clock``
message ``{device_sample, server_time_s}`` pairs a counter value with the server's
monotonic time, and displays map their own clock onto the server's with ping/pong
(NTP-style offset from the lowest-RTT exchanges) to know the device sample "now".

* :class:`SimulatedDevice` plays in real time on the monotonic clock (no hardware): it is
  what tests, benches and servers without a sound card use.
* :class:`SoundDevice` plays through PortAudio via the optional ``sounddevice`` package
  and reads its position from the stream's own clock.
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Protocol

import numpy as np

log = logging.getLogger("lipclock.clock")


class Device(Protocol):
    sample_rate: int

    def enqueue(self, samples: np.ndarray) -> int:
        """Queue int16 samples to play after what is queued; return their first device sample."""

    def position(self) -> tuple[int, float]:
        """(device sample being played, monotonic time in s that it refers to)."""

    def stop(self) -> int:
        """Drop everything queued; return the device sample where output stopped."""

    def close(self) -> None: ...


class SimulatedDevice:
    """A device that 'plays' queued samples in real time and idles (clock still) when empty."""

    def __init__(self, sample_rate: int) -> None:
        self.sample_rate = sample_rate
        self._lock = threading.Lock()
        self._base_sample = 0  # device sample at _base_time
        self._base_time = time.monotonic()
        self._queued_until = 0  # device sample where queued audio ends

    def _now_sample(self, now: float) -> int:
        played = self._base_sample + int((now - self._base_time) * self.sample_rate)
        return min(played, max(self._queued_until, self._base_sample))

    def position(self) -> tuple[int, float]:
        with self._lock:
            now = time.monotonic()
            return self._now_sample(now), now

    def enqueue(self, samples: np.ndarray) -> int:
        with self._lock:
            now = time.monotonic()
            current = self._now_sample(now)
            if self._queued_until <= current:  # idle: playback (re)starts now
                self._base_sample, self._base_time = current, now
                self._queued_until = current
            first = self._queued_until
            self._queued_until += len(samples)
            return first

    def stop(self) -> int:
        with self._lock:
            now = time.monotonic()
            current = self._now_sample(now)
            self._base_sample, self._base_time = current, now
            self._queued_until = current
            return current

    def close(self) -> None:
        pass


class SoundDevice:
    """PortAudio output through ``sounddevice``; position from the stream's DAC clock."""

    def __init__(self, sample_rate: int, device: str | int | None = None) -> None:
        import sounddevice as sd  # optional dependency: lipclock[device]

        self.sample_rate = sample_rate
        self._buf = np.zeros(0, dtype=np.int16)
        self._lock = threading.Lock()
        self._played = 0
        self._stream = sd.OutputStream(samplerate=sample_rate, channels=1, dtype="int16",
                                       device=device, callback=self._callback)
        self._stream.start()

    def _callback(self, outdata, frames, time_info, status) -> None:  # type: ignore[no-untyped-def]
        with self._lock:
            n = min(frames, len(self._buf))
            outdata[:n, 0] = self._buf[:n]
            outdata[n:, 0] = 0
            self._buf = self._buf[n:]
            self._played += frames

    def position(self) -> tuple[int, float]:
        with self._lock:
            latency = float(self._stream.latency or 0.0)
            return max(0, self._played - int(latency * self.sample_rate)), time.monotonic()

    def enqueue(self, samples: np.ndarray) -> int:
        with self._lock:
            first = self._played + len(self._buf)
            self._buf = np.concatenate([self._buf, samples.astype(np.int16)])
            return first

    def stop(self) -> int:
        with self._lock:
            self._buf = np.zeros(0, dtype=np.int16)
            return self._played

    def close(self) -> None:
        self._stream.stop()
        self._stream.close()


def open_device(sample_rate: int, name: str) -> Device:
    """'simulated', 'auto' (PortAudio if available, else simulated) or a PortAudio device."""
    if name == "simulated":
        return SimulatedDevice(sample_rate)
    try:
        return SoundDevice(sample_rate, None if name == "auto" else name)
    except Exception as exc:  # no sounddevice package, no PortAudio, no such device
        if name != "auto":
            raise
        log.warning("no audio output (%s): using a simulated device clock", exc)
        return SimulatedDevice(sample_rate)
