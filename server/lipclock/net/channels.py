"""In-process channels: fan-out of utterances to WebSocket subscribers.

Each channel plays its utterances one at a time from a bounded queue. For
every audio chunk it first broadcasts the mouth frames covering that stretch
of samples, then the audio, so mouth data never arrives after its audio.
Every subscriber has a bounded queue; one that falls behind is marked for
closing with code 4008 and never slows the others.
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import logging
import re
import time
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..utterance import Prepared
from .clock import Device
from .protocol import End, Mouth, Start, pack_audio

log = logging.getLogger("lipclock.channels")
CLOSE_TOO_SLOW = 4008  # documented in docs/protocol.md
CHANNEL_RE = re.compile(r"^[A-Za-z0-9_.-]{1,64}$")  # what a channel may be called
_ids = itertools.count(1)


def next_utterance_id() -> int:
    return next(_ids) & 0xFFFFFFFF


class ChannelBusy(Exception):
    """The channel already has its maximum number of queued utterances."""


class Subscriber:
    def __init__(self, max_queue: int) -> None:
        self.queue: asyncio.Queue[str | bytes | None] = asyncio.Queue(maxsize=max_queue)
        self.too_slow = False

    def offer(self, item: str | bytes) -> None:
        if self.too_slow:
            return
        try:
            self.queue.put_nowait(item)
        except asyncio.QueueFull:
            self.too_slow = True
            with contextlib.suppress(asyncio.QueueFull):
                self.queue.get_nowait()  # make room for the close marker
                self.queue.put_nowait(None)


@dataclass
class Job:
    utterance_id: int
    prepared: Prepared
    stop: asyncio.Event = field(default_factory=asyncio.Event)
    device_start: int | None = None
    device_stopped_at: int | None = None
    first_sent_at: float | None = None  # monotonic time the first audio went out

    def cut_sample(self, device_at: int | None, now: float) -> int | None:
        """Where a stop at this moment cuts this utterance, or None if it has finished.

        Device mode: the device position. Client mode: the server cannot see the
        browsers' clocks, so it estimates from the time since the first audio went out;
        clients stop at once on a stopped end anyway."""
        n = self.prepared.num_samples
        if device_at is not None and self.device_start is not None:
            cut = device_at - self.device_start
        elif self.first_sent_at is not None:
            cut = int((now - self.first_sent_at) * self.prepared.sample_rate)
        else:
            return None
        return max(0, cut) if cut < n else None


class Channel:
    def __init__(self, name: str, max_queued: int, device: Device | None = None) -> None:
        self.name = name
        self.device = device  # device mode: audio plays here too
        self.subscribers: set[Subscriber] = set()
        self.pending: asyncio.Queue[Job] = asyncio.Queue(maxsize=max_queued)
        self.current: Job | None = None
        self.worker: asyncio.Task[None] | None = None
        self.streamed: list[Job] = []  # fully streamed, maybe still playing

    def broadcast(self, item: str | bytes) -> None:
        for sub in list(self.subscribers):
            sub.offer(item)

    def enqueue(self, job: Job) -> None:
        try:
            self.pending.put_nowait(job)
        except asyncio.QueueFull:
            raise ChannelBusy(f"channel {self.name!r} already has {self.pending.maxsize} "
                              "utterances queued") from None
        if self.worker is None or self.worker.done():
            self.worker = asyncio.get_running_loop().create_task(self._run())

    def stop(self) -> None:
        """Barge-in: cut the current utterance and drop the queued ones."""
        while not self.pending.empty():
            self.pending.get_nowait()
        at = self.device.stop() if self.device is not None else None
        if self.current is not None:
            self.current.stop.set()
            self.current.device_stopped_at = at
        # Streaming runs far ahead of playback, so utterances already streamed may still be
        # playing (or queued on the device): tell every client where each was cut.
        now = time.monotonic()
        for job in self.streamed:
            cut = job.cut_sample(at, now)
            if cut is not None:
                self.broadcast(End(utterance_id=job.utterance_id, end_sample=cut,
                                   stopped=True).model_dump_json())
        self.streamed.clear()

    async def _run(self) -> None:
        while not self.pending.empty():
            job = self.pending.get_nowait()
            self.current = job
            try:
                await self._play(job)
            except Exception:  # a bug in one utterance must not kill the channel
                log.exception("utterance %s failed", job.utterance_id)
                self.broadcast(End(utterance_id=job.utterance_id, end_sample=0,
                                   stopped=True).model_dump_json())
            finally:
                self.current = None

    async def _play(self, job: Job) -> None:
        prep = job.prepared
        chunks = prep.audio_chunks()
        mouth = prep.mouth
        sent_frames = 0
        end_sample = 0
        take = 2  # the first thread hop renders the first two chunks (all of second 0)
        started = False
        while not job.stop.is_set():
            batch = await asyncio.to_thread(_take, chunks, take)
            take = 1
            if not batch or job.stop.is_set():
                break
            if self.device is not None:
                for chunk in batch:
                    first = self.device.enqueue(chunk.samples)
                    if job.device_start is None:
                        job.device_start = first
            if not started:  # in device mode the start message carries the device sample
                self.broadcast(start_message(job.utterance_id, prep, job.device_start)
                               .model_dump_json())
                started = True
                job.first_sent_at = time.monotonic()
            for chunk in batch:
                lo, hi = mouth.frame_range(0, chunk.end_sample)
                if hi > sent_frames:
                    self.broadcast(mouth_message(job.utterance_id, prep, sent_frames, hi)
                                   .model_dump_json())
                    sent_frames = hi
                self.broadcast(pack_audio(job.utterance_id, chunk.start_sample,
                                          chunk.samples.astype("<i2").tobytes()))
                end_sample = chunk.end_sample
        if not started:
            self.broadcast(start_message(job.utterance_id, prep, job.device_start)
                           .model_dump_json())
        stopped = job.stop.is_set() and end_sample < prep.num_samples
        if job.device_stopped_at is not None and job.device_start is not None:
            # device mode: the cut is where the speaker actually stopped
            end_sample = max(0, min(end_sample, job.device_stopped_at - job.device_start))
            stopped = True
        elif not stopped:
            at = self.device.position()[0] if self.device is not None else None
            now = time.monotonic()
            self.streamed = [j for j in self.streamed if j.cut_sample(at, now) is not None]
            self.streamed.append(job)
        self.broadcast(End(utterance_id=job.utterance_id, end_sample=end_sample,
                           stopped=stopped).model_dump_json())


def _take(chunks: Any, n: int) -> list[Any]:
    return list(itertools.islice(chunks, n))


def start_message(uid: int, prep: Prepared, device_start: int | None = None) -> Start:
    m = prep.marks(mouth=False)
    return Start(utterance_id=uid, sample_rate=prep.sample_rate, num_samples=prep.num_samples,
                 text=prep.text, voice=prep.voice, words=m["words"], phones=m["phones"],
                 visemes=m["visemes"], mouth_nodes=list(prep.mouth.nodes),
                 mouth_rate_hz=prep.mouth.rate_hz, device_start=device_start)


def mouth_message(uid: int, prep: Prepared, lo: int, hi: int) -> Mouth:
    mouth = prep.mouth
    end = mouth.frame_sample(hi) if hi < mouth.n_frames else prep.num_samples
    return Mouth(utterance_id=uid, first_frame=lo, first_sample=mouth.frame_sample(lo),
                 end_sample=end, frames=np.round(mouth.frames[lo:hi], 2).tolist(),
                 lip_gap=np.round(mouth.measures["lip_gap"][lo:hi], 3).tolist(),
                 width=np.round(mouth.measures["width"][lo:hi], 3).tolist(),
                 jaw=np.round(mouth.measures["jaw"][lo:hi], 3).tolist())


class Broker:
    """All channels of this process (the embedded default: no external service)."""

    def __init__(self, max_queued: int, device: Device | None = None) -> None:
        self.channels: dict[str, Channel] = {}
        self.max_queued = max_queued
        self.device = device

    def channel(self, name: str) -> Channel:
        ch = self.channels.get(name)
        if ch is None:
            ch = self.channels[name] = Channel(name, self.max_queued, self.device)
        return ch

    def broadcast_all(self, item: str | bytes) -> None:
        for ch in self.channels.values():
            ch.broadcast(item)

    def drop_if_idle(self, name: str) -> None:
        ch = self.channels.get(name)
        if ch and not ch.subscribers and ch.current is None and ch.pending.empty():
            del self.channels[name]


class UtteranceStore:
    """The most recent utterances, for /utterances/{id}.wav and marks (LRU by count)."""

    def __init__(self, capacity: int) -> None:
        self.capacity = capacity
        self.items: OrderedDict[int, Prepared] = OrderedDict()

    def put(self, uid: int, prep: Prepared) -> None:
        self.items[uid] = prep
        self.items.move_to_end(uid)
        while len(self.items) > self.capacity:
            self.items.popitem(last=False)

    def get(self, uid: int) -> Prepared | None:
        return self.items.get(uid)


def summary(uid: int, prep: Prepared) -> dict[str, Any]:
    m = prep.marks(mouth=False)
    return {"utterance_id": uid, "sample_rate": prep.sample_rate,
            "duration_s": round(prep.duration_s, 4), "words": m["words"],
            "phones": m["phones"], "visemes": m["visemes"]}
