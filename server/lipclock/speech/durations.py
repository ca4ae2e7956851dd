"""Segment durations: Klatt's duration rules as published for MITalk.

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
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from ..errors import TableError
from ..tables import iter_tsv, package_file
from .phoneset import PAUSE, phones
from .phrasing import Phrase

MIN_SEGMENT_S = 0.015  # floor so every phone spans at least three 5 ms frames


@dataclass(frozen=True, slots=True)
class SegmentDuration:
    inherent_ms: float
    minimum_ms: float
    unstressed_inherent_ms: float
    unstressed_minimum_ms: float


@cache
def duration_table() -> dict[str, SegmentDuration]:
    return load_durations(package_file("lipclock.speech", "data/durations.tsv"))


def load_durations(path: Path) -> dict[str, SegmentDuration]:
    known = phones()
    table: dict[str, SegmentDuration] = {}
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
        table[name] = SegmentDuration(inh, mn, u_inh, u_mn)
    missing = sorted(set(known) - set(table) - {PAUSE})
    if missing:
        raise TableError(path, 1, f"no durations for phones: {' '.join(missing)}")
    return table


_VOICED_FRIC = {"V", "DH", "Z", "ZH"}
_VOICED_STOP = {"B", "D", "G", "JH"}
_VOICELESS_STOP = {"P", "T", "K", "CH"}
_NASAL = {"M", "N", "NG"}
_LIQ_GLIDE = {"L", "R", "W", "Y"}
_ASPIRATING = {"P", "T", "K"}


def phrase_durations_s(phrase: Phrase, scale: float) -> list[list[float]]:
    """Duration in seconds of every phone of every word in the phrase (Klatt rules)."""
    table = duration_table()
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
