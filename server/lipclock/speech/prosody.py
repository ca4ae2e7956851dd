"""Prosody: pronounced words -> Timeline (phone durations on the sample clock + F0 targets).

Segment durations come from Klatt's MITalk rules (speech/durations.py); phrases and
their kinds from speech/phrasing.py.

The speaking rate scales segment durations by ``NATURAL_WPM / rate_wpm``:
``rate_wpm`` is the articulation rate (pauses excluded); pauses are the
caller's ``comma_pause_s`` / ``period_pause_s`` as given (DECface offered both).

F0 is a target-point contour in semitones around the voice's base pitch:
declination over each phrase, a peak on each accented (primary-stressed
content-word) vowel with successive peaks stepping down, a final fall for
statements and wh-questions, a rise for yes/no questions and a small
continuation rise at commas, colons and dashes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache

from ..errors import OutOfRangeError
from ..tables import package_file
from .durations import phrase_durations_s
from .phoneset import PAUSE
from .phrasing import pause_s, split_phrases
from .timeline import F0Point, PhoneSpan, PhraseKind, PhraseSpan, Timeline, WordSpan
from .tokens import Pronounced

# Words per minute that the MITalk rules produce at PRCNT scale 1.0, measured on
# varied prose with bench/bench_frontend.py --calibrate (articulation rate,
# pauses excluded). rate_wpm scales segment durations relative to this.
NATURAL_WPM = 182.0
RATE_WPM_RANGE = (80.0, 450.0)
PITCH_HZ_RANGE = (50.0, 400.0)
LEAD_SILENCE_S = 0.05
TAIL_SILENCE_S = 0.12


@dataclass(frozen=True, slots=True)
class ProsodySettings:
    sample_rate: int = 16000
    rate_wpm: float = 170.0
    base_f0_hz: float = 110.0
    f0_range_st: float = 6.0
    comma_pause_s: float = 0.25
    period_pause_s: float = 0.55

    def __post_init__(self) -> None:
        lo, hi = RATE_WPM_RANGE
        if not (lo <= self.rate_wpm <= hi):
            raise OutOfRangeError("rate_wpm", self.rate_wpm, lo, hi)
        lo, hi = PITCH_HZ_RANGE
        if not (lo <= self.base_f0_hz <= hi):
            raise OutOfRangeError("pitch_hz", self.base_f0_hz, lo, hi)
        for name in ("comma_pause_s", "period_pause_s"):
            value = getattr(self, name)
            if not (0.0 <= value <= 5.0):
                raise OutOfRangeError(name, value, 0.0, 5.0)


@cache
def function_words() -> frozenset[str]:
    path = package_file("lipclock.speech", "data/function_words.txt")
    words = set()
    for line in path.read_text(encoding="utf-8").splitlines():
        word = line.split("#", 1)[0].strip()
        if word:
            words.add(word)
    return frozenset(words)


# --- durations --------------------------------------------------------------

# --- the Timeline -----------------------------------------------------------

def build_timeline(items: Sequence[Pronounced], s: ProsodySettings) -> Timeline:
    """Place phones, words, pauses and F0 targets on the integer sample clock.

    Boundaries are rounded from cumulative seconds, so rounding never drifts.
    """
    sr = s.sample_rate
    scale = NATURAL_WPM / s.rate_wpm
    fw = function_words()
    phone_spans: list[PhoneSpan] = []
    word_spans: list[WordSpan] = []
    phrase_spans: list[PhraseSpan] = []
    f0: list[F0Point] = []
    t = 0.0
    pos = 0

    def pause(dur_s: float) -> None:
        nonlocal t, pos
        t += dur_s
        end = max(pos, round(t * sr))
        phone_spans.append(PhoneSpan(PAUSE, pos, end, -1))
        pos = end

    base_hz = s.base_f0_hz
    pause(LEAD_SILENCE_S)
    phrases = split_phrases(items)
    for n, phrase in enumerate(phrases):
        durs = phrase_durations_s(phrase, scale)
        start = pos
        vowels: list[tuple[PhoneSpan, bool]] = []  # (span, accented)
        single = len(phrase.words) == 1
        for word, wd in zip(phrase.words, durs, strict=True):
            wi = len(word_spans)
            first = pos
            accentable = word.text not in fw or single
            for ph, d in zip(word.phones, wd, strict=True):  # the phones, inline: hot
                t += d
                end = round(t * sr)
                if end < pos:  # max(pos, ...) without the call
                    end = pos
                span = PhoneSpan(ph, pos, end, wi)
                phone_spans.append(span)
                pos = end
                if ph[-1].isdigit():
                    vowels.append((span, accentable and ph[-1] == "1"))
            word_spans.append(WordSpan(word.text, first, pos, word.orth, word.source))
        phrase_spans.append(PhraseSpan(start, pos, phrase.kind))
        f0.extend(_phrase_f0(start, pos, vowels, phrase.kind, s, sr))
        is_last = n == len(phrases) - 1
        gap = TAIL_SILENCE_S if is_last else pause_s(phrase.end, s.comma_pause_s,
                                                          s.period_pause_s)
        if gap > 0:
            pause(gap)
    if not phrases:
        pause(TAIL_SILENCE_S)
    f0.sort(key=lambda p: p.sample)
    if not f0:
        f0 = [F0Point(0, base_hz)]
    return Timeline(sr, tuple(phone_spans), tuple(word_spans), tuple(f0), tuple(phrase_spans))


def _phrase_f0(start: int, end: int, vowels: list[tuple[PhoneSpan, bool]], kind: PhraseKind,
               s: ProsodySettings, sr: int) -> list[F0Point]:
    """Target points (semitones around the base) for one phrase."""
    rng = s.f0_range_st * (1.3 if kind is PhraseKind.EXCLAMATION else 1.0)
    length_s = max(1e-3, (end - start) / sr)
    decl_st = -min(3.0, 1.2 * length_s)  # baseline drift over the phrase

    def base_st(sample: int) -> float:
        return 0.15 * rng + decl_st * (sample - start) / max(1, end - start)

    pts: list[tuple[int, float]] = [(start, base_st(start))]
    accents = [v for v, acc in vowels if acc]
    if not accents and vowels:  # every phrase gets at least one accent
        accents = [max(vowels, key=lambda va: va[0].num_samples)[0]]
    last_accent = accents[-1] if accents else None
    for i, v in enumerate(accents):
        height = rng * 0.6 * max(0.45, 0.82**i)
        if kind is PhraseKind.QUESTION and v is last_accent:
            continue  # the final rise replaces the last peak
        peak = v.start + int(0.35 * v.num_samples)
        pts.append((v.start, base_st(v.start) + 0.35 * height))
        pts.append((peak, base_st(peak) + height))
        pts.append((v.end, base_st(v.end) + 0.45 * height))
    final_v = vowels[-1][0] if vowels else None
    if kind in (PhraseKind.STATEMENT, PhraseKind.WH_QUESTION, PhraseKind.EXCLAMATION):
        pts.append((end, base_st(end) - 0.45 * rng))
    elif kind is PhraseKind.QUESTION:
        anchor = last_accent or final_v
        a = anchor.start if anchor else start
        pts.append((a, base_st(a) - 0.1 * rng))
        pts.append((end, base_st(end) + 0.9 * rng))
    elif kind is PhraseKind.CONTINUATION:
        if final_v is not None:
            pts.append((final_v.start, base_st(final_v.start)))
        pts.append((end, base_st(end) + 0.35 * rng))
    else:
        pts.append((end, base_st(end) - 0.2 * rng))
    pts.sort(key=lambda p: p[0])
    return [F0Point(x, s.base_f0_hz * math.pow(2.0, st / 12.0)) for x, st in pts]

