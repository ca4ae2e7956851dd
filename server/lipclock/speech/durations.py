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

from dataclasses import dataclass
from functools import cache
from pathlib import Path

from ..errors import TableError
from ..tables import iter_tsv, package_file
from .phoneset import PAUSE, phones, written_forms
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


def _rule9_factor(base: str | None) -> float:
    """Rule 9: a vowel's factor from the consonant after it in the word."""
    if base in _VOICED_FRIC:
        return 1.6
    if base in _VOICED_STOP:
        return 1.2
    if base in _NASAL:
        return 0.85
    if base in _VOICELESS_STOP:
        return 0.7
    return 1.0


@dataclass(frozen=True, slots=True)
class _Segment:
    """What the rules read of one phone string, looked up once per string."""

    base: str
    vowel: bool
    stressed: bool  # vowels: stress 1 or 2 (consonants take their syllable's)
    inherent_ms: float  # a vowel with stress 0 has the unstressed pair here
    minimum_ms: float
    liquid: bool  # in _LIQ_GLIDE
    nasal_or_liquid: bool
    aspirating: bool
    rule9: float  # factor for a vowel before this phone in the same word


def _segment(phone: str, table: dict[str, SegmentDuration]) -> _Segment:
    b = phone.rstrip("012")
    vowel = phone[-1].isdigit()
    d = table[b]
    inh, mn = d.inherent_ms, d.minimum_ms
    if vowel and phone[-1] == "0":
        inh, mn = d.unstressed_inherent_ms, d.unstressed_minimum_ms
    return _Segment(b, vowel, vowel and phone[-1] in "12", inh, mn, b in _LIQ_GLIDE,
                    b in _NASAL or b in _LIQ_GLIDE, b in _ASPIRATING, _rule9_factor(b))


@cache
def _segments() -> dict[str, _Segment]:
    """_segment for every phone string in the table, with and without stress digits."""
    table = duration_table()
    return {s: _segment(s, table) for ph in table for s in written_forms(ph)}


def phrase_durations_s(phrase: Phrase, scale: float) -> list[list[float]]:
    """Duration in seconds of every phone of every word in the phrase (Klatt rules)."""
    segs = _segments()
    table = duration_table()
    words = phrase.words
    flat = [segs.get(ph) or _segment(ph, table) for w in words for ph in w.phones]
    n = len(flat)
    last_word = len(words) - 1
    has_end = phrase.end is not None
    out: list[list[float]] = []
    k = 0  # index into flat: rules 10 and 11 look across word boundaries
    for wi, word in enumerate(words):
        m = len(word.phones)
        ws = flat[k:k + m]
        vidx = [i for i, sg in enumerate(ws) if sg.vowel]
        last_v = vidx[-1] if vidx else -1
        first_v = vidx[0] if vidx else m
        poly = len(vidx) > 1
        final_word = wi == last_word
        # a consonant counts as stressed if the nearest following vowel (else the
        # word's last vowel) is
        stressed = [False] * m
        cur = bool(vidx) and ws[last_v].stressed
        for i in range(m - 1, -1, -1):
            if ws[i].vowel:
                cur = ws[i].stressed
            stressed[i] = cur
        row = [0.0] * m
        for pi, sg in enumerate(ws):
            pfs = final_word and pi >= last_v  # in the phrase-final syllable
            inh, mn = sg.inherent_ms, sg.minimum_ms
            prcnt = 1.0
            if sg.vowel:
                if pfs and has_end:
                    prcnt *= 1.4  # rule 2
                if not pfs:
                    prcnt *= 0.6  # rule 3
                if pi != last_v:
                    prcnt *= 0.85  # rule 4
                if poly:
                    prcnt *= 0.8  # rule 5
                if not sg.stressed:  # rule 7
                    mn *= 0.5
                    prcnt *= 0.5 if (pi != last_v and pi != first_v) else 0.7
                f = ws[pi + 1].rule9 if pi + 1 < m else 1.0  # rule 9
                prcnt *= f if pfs else 0.7 + 0.3 * f
                if k + 1 < n and flat[k + 1].vowel:  # rule 10
                    prcnt *= 1.2
                if k > 0 and flat[k - 1].vowel:
                    prcnt *= 0.7
            else:
                postvocalic = pi > last_v >= 0
                if pfs and has_end and postvocalic:
                    prcnt *= 1.4  # rule 2
                if postvocalic and pfs and sg.nasal_or_liquid:
                    prcnt *= 1.4  # rule 3, liquids and nasals
                if pi != 0:
                    prcnt *= 0.85  # rule 6
                if not stressed[pi]:  # rule 7
                    mn *= 0.5
                    if sg.liquid and pi + 1 < m and ws[pi + 1].vowel:
                        prcnt *= 0.1
                    else:
                        prcnt *= 0.7
                prev_c = k > 0 and not flat[k - 1].vowel  # rule 10
                next_c = k + 1 < n and not flat[k + 1].vowel
                if prev_c and next_c:
                    prcnt *= 0.5
                elif prev_c or next_c:
                    prcnt *= 0.7
            dur_ms = mn + (inh - mn) * prcnt
            if stressed[pi] and k > 0 and flat[k - 1].aspirating and (sg.vowel or sg.liquid):
                dur_ms += 25.0  # rule 11
            dur_s = dur_ms * 0.001 * scale
            row[pi] = dur_s if dur_s > MIN_SEGMENT_S else MIN_SEGMENT_S
            k += 1
        out.append(row)
    return out
