"""Results of synthesis: :class:`Prepared` (before audio) and :class:`Utterance` (with audio).

The marks dict follows DESIGN.md: ``sample_rate``; ``words``, ``phones`` and
``visemes`` with ``start``/``end`` in samples; ``mouth`` with ``rate_hz``,
``nodes``, ``frames`` and ``measures`` (frame k at sample
``round(k * sample_rate / rate_hz)``).
"""

from __future__ import annotations

import wave
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from .engine import Work, render_all, render_chunks
from .speech.phoneset import PAUSE
from .speech.timeline import PhoneSpan, Timeline, WordSpan


@dataclass(frozen=True, slots=True)
class AudioChunk:
    start_sample: int
    samples: np.ndarray  # int16, mono

    @property
    def end_sample(self) -> int:
        return self.start_sample + len(self.samples)


def write_wav(path: str | Path | BinaryIO, samples: np.ndarray, sample_rate: int) -> None:
    """Write mono 16-bit PCM to a path or a binary file object."""
    target = str(path) if isinstance(path, (str, Path)) else path
    with wave.open(target, "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(sample_rate)
        w.writeframes(np.asarray(samples, dtype="<i2").tobytes())


def wav_bytes(samples: np.ndarray, sample_rate: int) -> bytes:
    import io

    buf = io.BytesIO()
    write_wav(buf, samples, sample_rate)
    return buf.getvalue()


class _Marks:
    """Shared accessors for Prepared and Utterance."""

    timeline: Timeline
    visemes: tuple[Any, ...]
    mouth: Any
    voice: str

    @property
    def sample_rate(self) -> int:
        return self.timeline.sample_rate

    @property
    def num_samples(self) -> int:
        return self.timeline.num_samples

    @property
    def duration_s(self) -> float:
        return self.timeline.duration_s

    @property
    def phones(self) -> tuple[PhoneSpan, ...]:
        return self.timeline.phones

    @property
    def words(self) -> tuple[WordSpan, ...]:
        return self.timeline.words

    def marks(self, fmt: str | None = None, *, mouth: bool = True) -> dict[str, Any]:
        """The marks dict (DESIGN.md contract); ``fmt`` adds one export under ``export``.

        ``mouth=False`` leaves out the trajectories (cheap: for streaming headers)."""
        tl = self.timeline
        out: dict[str, Any] = {
            "sample_rate": tl.sample_rate,
            "num_samples": tl.num_samples,
            "voice": self.voice,
            "words": [{"text": w.text, "orth": w.orth, "start": w.start, "end": w.end}
                      for w in tl.words],
            "phones": [{"phone": p.phone, "start": p.start, "end": p.end,
                        "word": p.word} for p in tl.phones],
            "visemes": [{"viseme": v.viseme, "phone": v.phone, "start": v.start, "end": v.end}
                        for v in self.visemes],
        }
        if mouth:
            out["mouth"] = self.mouth.to_marks()
        if fmt:
            from .face.exports import export

            out["export"] = {"format": fmt,
                             "data": export(fmt, tl, self.visemes, self.mouth)}
        return out

    def phone_string(self) -> str:
        return " ".join(p.phone for p in self.timeline.phones if p.phone != PAUSE)


@dataclass(frozen=True)
class Utterance(_Marks):
    text: str
    voice: str
    timeline: Timeline
    visemes: tuple[Any, ...]
    mouth: Any
    samples: np.ndarray  # int16

    def write_wav(self, path: str | Path) -> None:
        write_wav(path, self.samples, self.sample_rate)

    def wav_bytes(self) -> bytes:
        return wav_bytes(self.samples, self.sample_rate)


@dataclass(frozen=True)
class Prepared(_Marks):
    """Everything but the audio: cheap to compute, so a server can send marks first."""

    text: str
    voice: str
    timeline: Timeline
    visemes: tuple[Any, ...]
    mouth: Any
    work: Work

    @classmethod
    def from_work(cls, text: str, work: Work) -> Prepared:
        assert work.timeline is not None
        voice = work.request.system_voice or work.request.voice.name
        return cls(text, voice, work.timeline, work.visemes, work.mouth, work)

    def audio_chunks(self) -> Iterator[AudioChunk]:
        """Audio in order; the chunks concatenate to exactly :meth:`render`'s samples."""
        for start, samples in render_chunks(self.work):
            yield AudioChunk(start, samples)

    def render(self) -> Utterance:
        samples = render_all(self.work)  # the same samples as audio_chunks(), concatenated
        return Utterance(self.text, self.voice, self.timeline, self.visemes, self.mouth, samples)
