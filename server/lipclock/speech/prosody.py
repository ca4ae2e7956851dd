"""Prosody: pronounced words -> Timeline (phone durations on the sample clock + F0 targets).

Durations follow Klatt's rules as published for MITalk (Allen, Hunnicutt &
Klatt 1987, ch. 9; Klatt 1979): each segment has an inherent and a minimum
duration (``data/durations.tsv``) and
``DUR = MINDUR + (INHDUR - MINDUR) * PRCNT / 100``, where PRCNT is the product
of the context rules below (numbered as in MITalk):

2. clause-final lengthening (x1.4 for the vowel and post-vocalic consonants of a
   phrase-final syllable);
3. non-phrase-final shortening of vowels (x0.6); phrase-final post-vocalic
   liquids and nasals lengthened (x1.4);
4. non-word-final shortening of vowels (x0.85);
5. polysyllabic shortening of vowels (x0.8);
6. non-initial consonant shortening (x0.85);
7. unstressed segments: MINDUR halved; vowels x0.5 word-medially, else x0.7;
   prevocalic liquids/glides in unstressed syllables x0.1;
9. post-vocalic context of vowels: voiced fricative x1.6, voiced plosive x1.2,
   nasal x0.85, voiceless plosive x0.7 — fully phrase-finally, as
   ``0.7 + 0.3 * f`` elsewhere;
10. clusters: vowel before vowel x1.2, vowel after vowel x0.7, consonant between
    consonants x0.5, consonant next to a consonant x0.7;
11. +25 ms for a stressed vowel or sonorant after a voiceless plosive (aspiration).

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
from pathlib import Path

from ..errors import OutOfRangeError, TableError
from ..tables import iter_tsv, package_file
from .phoneset import PAUSE, info, phones
from .timeline import F0Point, PhoneSpan, PhraseKind, PhraseSpan, Timeline, WordSpan
from .tokens import BreakKind, BreakToken, Pronounced, PronouncedWord

# Words per minute that the MITalk rules produce at PRCNT scale 1.0, measured on
# varied prose with bench/bench_frontend.py --calibrate (articulation rate,
# pauses excluded). rate_wpm scales segment durations relative to this.
NATURAL_WPM = 182.0
RATE_WPM_RANGE = (80.0, 450.0)
PITCH_HZ_RANGE = (50.0, 400.0)
MIN_SEGMENT_S = 0.015  # floor so every phone spans at least three 5 ms frames
LEAD_SILENCE_S = 0.05
TAIL_SILENCE_S = 0.12

WH_WORDS = frozenset({"who", "what", "when", "where", "why", "how", "which", "whose", "whom"})


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


@dataclass(frozen=True, slots=True)
class _Dur:
    inherent_ms: float
    minimum_ms: float
    unstressed_inherent_ms: float
    unstressed_minimum_ms: float


@cache
def _durations() -> dict[str, _Dur]:
    return load_durations(package_file("lipclock.speech", "data/durations.tsv"))


def load_durations(path: Path) -> dict[str, _Dur]:
    known = phones()
    table: dict[str, _Dur] = {}
    for line, fields in iter_tsv(path):
        if len(fields) != 5:
            raise TableError(path, line, f"expected 5 columns, got {len(fields)}")
        name = fields[0]
        if name not in known or name == PAUSE:
            raise TableError(path, line, f"unknown phone {name!r}")
        try:
            inh, mn = float(fields[1]), float(fields[2])
            u_inh = inh if fields[3] == "-" else float(fields[3])
            u_mn = mn if fields[4] == "-" else float(fields[4])
        except ValueError:
            raise TableError(path, line, "durations must be numbers (ms) or '-'") from None
        if not (0 < mn <= inh < 1000 and 0 < u_mn <= u_inh < 1000):
            raise TableError(path, line, "need 0 < minimum <= inherent < 1000 ms")
        table[name] = _Dur(inh, mn, u_inh, u_mn)
    missing = sorted(set(known) - set(table) - {PAUSE})
    if missing:
        raise TableError(path, 1, f"no durations for phones: {' '.join(missing)}")
    return table


@cache
def function_words() -> frozenset[str]:
    path = package_file("lipclock.speech", "data/function_words.txt")
    words = set()
    for line in path.read_text(encoding="utf-8").splitlines():
        word = line.split("#", 1)[0].strip()
        if word:
            words.add(word)
    return frozenset(words)


# --- phrasing -------------------------------------------------------------

@dataclass(frozen=True, slots=True)
class _Phrase:
    words: tuple[PronouncedWord, ...]
    end: BreakKind | None  # the break after the phrase (None: end of text)
    kind: PhraseKind


_CONTINUATION = {BreakKind.COMMA, BreakKind.PAREN, BreakKind.DASH, BreakKind.COLON,
                 BreakKind.SEMICOLON}
_SENTENCE_END = {BreakKind.PERIOD, BreakKind.QUESTION, BreakKind.EXCLAMATION,
                 BreakKind.PARAGRAPH, BreakKind.ELLIPSIS}


def split_phrases(items: Sequence[Pronounced]) -> list[_Phrase]:
    """Group words between breaks; label each phrase with how it ends."""
    phrases: list[_Phrase] = []
    current: list[PronouncedWord] = []
    sentence_first: str | None = None
    for item in list(items) + [None]:
        if isinstance(item, PronouncedWord):
            if not item.phones:
                continue
            if sentence_first is None:
                sentence_first = item.text
            current.append(item)
            continue
        end = item.kind if isinstance(item, BreakToken) else None
        if current:
            phrases.append(_Phrase(tuple(current), end, _phrase_kind(end, sentence_first)))
            current = []
        elif phrases and end is not None and _strength(end) > _strength(phrases[-1].end):
            last = phrases[-1]  # "word ,." -> keep the stronger break
            phrases[-1] = _Phrase(last.words, end, _phrase_kind(end, sentence_first))
        if end is None or end in _SENTENCE_END:
            sentence_first = None
    return phrases


def _strength(kind: BreakKind | None) -> int:
    if kind is None:
        return 0
    return 2 if kind in _SENTENCE_END else 1


def _phrase_kind(end: BreakKind | None, sentence_first: str | None) -> PhraseKind:
    if end is None or end in (BreakKind.PERIOD, BreakKind.PARAGRAPH):
        return PhraseKind.STATEMENT
    if end is BreakKind.QUESTION:
        return PhraseKind.WH_QUESTION if sentence_first in WH_WORDS else PhraseKind.QUESTION
    if end is BreakKind.EXCLAMATION:
        return PhraseKind.EXCLAMATION
    if end is BreakKind.ELLIPSIS:
        return PhraseKind.NONE
    return PhraseKind.CONTINUATION


def pause_s(end: BreakKind | None, s: ProsodySettings) -> float:
    """Silence after a phrase ending in ``end``."""
    if end is None:
        return 0.0
    if end in (BreakKind.COMMA, BreakKind.PAREN, BreakKind.DASH):
        return s.comma_pause_s
    if end in (BreakKind.COLON, BreakKind.SEMICOLON):
        return 0.5 * (s.comma_pause_s + s.period_pause_s)
    if end is BreakKind.PARAGRAPH:
        return 1.5 * s.period_pause_s
    return s.period_pause_s


# --- durations --------------------------------------------------------------

_VOICED_FRIC = {"V", "DH", "Z", "ZH"}
_VOICED_STOP = {"B", "D", "G", "JH"}
_VOICELESS_STOP = {"P", "T", "K", "CH"}
_NASAL = {"M", "N", "NG"}
_LIQ_GLIDE = {"L", "R", "W", "Y"}
_ASPIRATING = {"P", "T", "K"}


def phrase_durations_s(phrase: _Phrase, scale: float) -> list[list[float]]:
    """Duration in seconds of every phone of every word in the phrase (Klatt rules)."""
    table = _durations()
    flat: list[tuple[int, int, str]] = []  # (word index, phone index, phone)
    for wi, word in enumerate(phrase.words):
        for pi, ph in enumerate(word.phones):
            flat.append((wi, pi, ph))
    bases = [ph.rstrip("012") for _, _, ph in flat]
    is_vowel = [ph[-1].isdigit() for _, _, ph in flat]
    last_word = len(phrase.words) - 1
    out: list[list[float]] = [[0.0] * len(w.phones) for w in phrase.words]

    # per-word syllable facts
    vowel_idx = [[i for i, p in enumerate(w.phones) if p[-1].isdigit()] for w in phrase.words]

    for k, (wi, pi, ph) in enumerate(flat):
        b = bases[k]
        vowel = is_vowel[k]
        word = phrase.words[wi]
        vidx = vowel_idx[wi]
        last_v = vidx[-1] if vidx else -1
        first_v = vidx[0] if vidx else len(word.phones)
        in_final_syll = pi >= last_v  # the word's last vowel and what follows it
        phrase_final_syll = wi == last_word and in_final_syll
        stressed = (ph[-1] in "12") if vowel else _syllable_stressed(word.phones, pi, vidx)
        d = table[b]
        inh, mn = (d.inherent_ms, d.minimum_ms)
        if vowel and ph[-1] == "0":
            inh, mn = d.unstressed_inherent_ms, d.unstressed_minimum_ms
        prcnt = 1.0
        postvocalic = (not vowel) and pi > last_v >= 0
        if phrase_final_syll and phrase.end is not None and (vowel or postvocalic):
            prcnt *= 1.4  # rule 2
        if vowel and not phrase_final_syll:
            prcnt *= 0.6  # rule 3
        if postvocalic and phrase_final_syll and (b in _NASAL or b in _LIQ_GLIDE):
            prcnt *= 1.4  # rule 3, liquids and nasals
        if vowel and pi != last_v:
            prcnt *= 0.85  # rule 4
        if vowel and len(vidx) > 1:
            prcnt *= 0.8  # rule 5
        if not vowel and pi != 0:
            prcnt *= 0.85  # rule 6
        if not stressed:  # rule 7
            mn *= 0.5
            if vowel:
                prcnt *= 0.5 if (pi != last_v and pi != first_v) else 0.7
            elif b in _LIQ_GLIDE and pi + 1 < len(word.phones) \
                    and word.phones[pi + 1][-1].isdigit():
                prcnt *= 0.1
            else:
                prcnt *= 0.7
        if vowel:  # rule 9
            nxt = bases[k + 1] if k + 1 < len(flat) and flat[k + 1][0] == wi else None
            f = 1.0
            if nxt in _VOICED_FRIC:
                f = 1.6
            elif nxt in _VOICED_STOP:
                f = 1.2
            elif nxt in _NASAL:
                f = 0.85
            elif nxt in _VOICELESS_STOP:
                f = 0.7
            prcnt *= f if phrase_final_syll else 0.7 + 0.3 * f
        prev_v = is_vowel[k - 1] if k > 0 else None
        next_v = is_vowel[k + 1] if k + 1 < len(flat) else None
        if vowel:  # rule 10
            if next_v:
                prcnt *= 1.2
            if prev_v:
                prcnt *= 0.7
        else:
            if prev_v is False and next_v is False:
                prcnt *= 0.5
            elif prev_v is False or next_v is False:
                prcnt *= 0.7
        dur_ms = mn + (inh - mn) * prcnt
        if stressed and k > 0 and bases[k - 1] in _ASPIRATING and (vowel or b in _LIQ_GLIDE):
            dur_ms += 25.0  # rule 11
        out[wi][pi] = max(MIN_SEGMENT_S, dur_ms * 0.001 * scale)
    return out


def _syllable_stressed(word_phones: Sequence[str], pi: int, vidx: Sequence[int]) -> bool:
    """A consonant counts as stressed if the nearest following vowel (else preceding) is."""
    for v in vidx:
        if v > pi:
            return word_phones[v][-1] in "12"
    return bool(vidx) and word_phones[vidx[-1]][-1] in "12"


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

    def emit(phone: str, dur_s: float, word: int) -> PhoneSpan:
        nonlocal t, pos
        t += dur_s
        end = max(pos, round(t * sr))
        span = PhoneSpan(phone, pos, end, word)
        phone_spans.append(span)
        pos = end
        return span

    base_hz = s.base_f0_hz
    emit(PAUSE, LEAD_SILENCE_S, -1)
    phrases = split_phrases(items)
    for n, phrase in enumerate(phrases):
        durs = phrase_durations_s(phrase, scale)
        start = pos
        vowels: list[tuple[PhoneSpan, bool]] = []  # (span, accented)
        for word, wd in zip(phrase.words, durs, strict=True):
            wi = len(word_spans)
            first = pos
            accentable = word.text not in fw or len(phrase.words) == 1
            for ph, d in zip(word.phones, wd, strict=True):
                span = emit(ph, d, wi)
                if ph[-1].isdigit():
                    vowels.append((span, accentable and ph[-1] == "1"))
            word_spans.append(WordSpan(word.text, first, pos, word.orth, word.source))
        phrase_spans.append(PhraseSpan(start, pos, phrase.kind))
        f0.extend(_phrase_f0(start, pos, vowels, phrase.kind, s, sr))
        is_last = n == len(phrases) - 1
        gap = TAIL_SILENCE_S if is_last else pause_s(phrase.end, s)
        if gap > 0:
            emit(PAUSE, gap, -1)
    if not phrases:
        emit(PAUSE, TAIL_SILENCE_S, -1)
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


def is_vowel_phone(phone: str) -> bool:
    return info(phone).is_vowel
