"""The Timeline: the immutable spine every later stage reads.

It holds words, phones (ARPAbet with stress, plus ``pau``) and F0 targets, all
placed at integer sample positions of one ``sample_rate``. Phones tile the
utterance: they are contiguous, start at sample 0 and end at ``num_samples``.
Nothing here reads a clock or does I/O.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np

from .phoneset import PAUSE, base, stress


class PhraseKind(StrEnum):
    """How a phrase ends; drives the final F0 movement and pause length."""

    STATEMENT = "statement"  # period: final fall
    QUESTION = "question"  # yes/no question: final rise
    WH_QUESTION = "wh_question"  # wh-question: falls like a statement
    EXCLAMATION = "exclamation"  # wider range, fall
    CONTINUATION = "continuation"  # comma, colon, semicolon, dash: small rise
    NONE = "none"  # text ended without punctuation


@dataclass(frozen=True, slots=True)
class PhoneSpan:
    phone: str  # "AH0", "S", "pau"
    start: int  # first sample (inclusive)
    end: int  # last sample (exclusive)
    word: int = -1  # index into Timeline.words; -1 for pauses

    @property
    def base(self) -> str:
        return base(self.phone)

    @property
    def stress(self) -> int | None:
        return stress(self.phone)

    @property
    def is_pause(self) -> bool:
        return self.phone == PAUSE

    @property
    def num_samples(self) -> int:
        return self.end - self.start


@dataclass(frozen=True, slots=True)
class WordSpan:
    text: str  # spoken form, lowercase ("nineteen")
    start: int
    end: int
    orth: str = ""  # the source text this word came from ("1993")
    source: str = ""  # where its pronunciation came from: user|cmudict|lts|compound|letter


@dataclass(frozen=True, slots=True)
class PhraseSpan:
    start: int
    end: int
    kind: PhraseKind


@dataclass(frozen=True, slots=True)
class F0Point:
    sample: int
    hz: float


@dataclass(frozen=True)
class Timeline:
    sample_rate: int
    phones: tuple[PhoneSpan, ...]
    words: tuple[WordSpan, ...] = ()
    f0: tuple[F0Point, ...] = ()
    phrases: tuple[PhraseSpan, ...] = ()
    _f0_arrays: tuple[np.ndarray, np.ndarray] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.sample_rate <= 0:
            raise ValueError("sample_rate must be positive")
        pos = 0
        for p in self.phones:
            if p.start != pos or p.end < p.start:
                raise ValueError(f"phones must tile the timeline: {p} does not start at {pos}")
            pos = p.end
        last = -1
        for pt in self.f0:
            if pt.sample < last:
                raise ValueError("F0 targets must be in sample order")
            last = pt.sample
        xs = np.fromiter((p.sample for p in self.f0), dtype=np.float64, count=len(self.f0))
        ys = np.fromiter((p.hz for p in self.f0), dtype=np.float64, count=len(self.f0))
        object.__setattr__(self, "_f0_arrays", (xs, ys))

    @property
    def num_samples(self) -> int:
        return self.phones[-1].end if self.phones else 0

    @property
    def duration_s(self) -> float:
        return self.num_samples / self.sample_rate

    def f0_at(self, samples: np.ndarray) -> np.ndarray:
        """F0 in Hz at the given sample positions, linear between targets (held at the ends)."""
        xs, ys = self._f0_arrays
        if len(xs) == 0:
            return np.zeros(np.shape(samples), dtype=np.float64)
        return np.interp(np.asarray(samples, dtype=np.float64), xs, ys)

    def phone_index_at(self, sample: int) -> int:
        """Index of the phone covering ``sample`` (clamped to the ends)."""
        ends = [p.end for p in self.phones]
        idx = int(np.searchsorted(ends, sample, side="right"))
        return min(idx, len(self.phones) - 1)
