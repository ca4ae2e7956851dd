"""``system:<id>`` voices: audio from the platform's speech engine via pyttsx3, timed by its events.

Issue 3, item 6. pyttsx3 names the voices the platform offers; the phone
timings for their audio come from the engine's own events, never from evenly
spaced guesses:

* **eSpeak-NG** (pyttsx3's driver on Linux): we drive the same library
  directly (:mod:`.espeak_events`) so one synthesis pass yields the audio and
  its phoneme events on the engine's sample clock. eSpeak mnemonics become
  ARPAbet through ``data/espeak_to_arpabet.tsv``. When one eSpeak phoneme
  stands for several ARPAbet phones (``A@`` -> ``AA1 R``) its measured span is
  shared in proportion to lipclock's inherent durations (MITalk, Allen,
  Hunnicutt & Klatt 1987, ``data/durations.tsv``).
* **Word events only** (SAPI5, NSSpeechSynthesizer): :func:`fit_phones_in_words`
  places each word's phones inside its measured boundaries with the same
  inherent-duration proportions. pyttsx3's public API does not pass those
  drivers' audio positions on, so until a driver adapter supplies them,
  :func:`synthesize_system` raises :class:`SystemVoiceError` there (see
  docs/voices.md) rather than inventing timings.

Positions are integer samples at the requested ``sample_rate``.
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from functools import cache
from math import gcd
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..errors import EmptyTextError, TableError, TextTooLongError, UnknownChoiceError
from ..tables import package_file
from .espeak_events import EngineEvent, SystemVoiceError, synthesize_events
from .phoneset import PAUSE, base, is_valid

PREFIX = "system:"
ABSORB = "-"
MAX_TEXT_CHARS = 5000

PhoneTiming = tuple[str, int, int]  # (ARPAbet phone, start sample, end sample)
WordTiming = tuple[str, int, int]  # (word, start sample, end sample)


class SystemSpeech(NamedTuple):
    samples: np.ndarray  # int16 mono
    sample_rate: int
    phones: list[PhoneTiming]  # contiguous, tiling [0, len(samples))
    words: list[WordTiming]


# --------------------------------------------------------------------------- tables

@cache
def espeak_map() -> dict[str, tuple[str, ...]]:
    """eSpeak mnemonic -> ARPAbet phones (``()`` = absorbed into the previous phone)."""
    return load_espeak_map(package_file("lipclock.speech", "data/espeak_to_arpabet.tsv"))


def _iter_rows(path: Path) -> Iterator[tuple[int, list[str]]]:
    """Like :func:`lipclock.tables.iter_tsv`, but ``#`` starts a comment only at the start
    of a line or after whitespace, because eSpeak mnemonics contain ``#`` (``t#``, ``a#``)."""
    for number, raw in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        line = re.split(r"(?:^|\s)#", raw, maxsplit=1)[0].rstrip()
        if line.strip():
            yield number, [f.strip() for f in line.split("\t")]


def load_espeak_map(path: Path) -> dict[str, tuple[str, ...]]:
    table: dict[str, tuple[str, ...]] = {}
    for line, fields in _iter_rows(path):
        if len(fields) != 2 or not fields[0] or not fields[1]:
            raise TableError(path, line, "expected: espeak_mnemonic<TAB>ARPAbet phones")
        key, phones = fields[0], fields[1].split()
        if key in table:
            raise TableError(path, line, f"duplicate eSpeak phoneme {key!r}")
        if phones == [ABSORB]:
            table[key] = ()
            continue
        for p in phones:
            if p != PAUSE and not is_valid(p):
                raise TableError(path, line, f"unknown ARPAbet phone {p!r} (vowels need 0/1/2)")
        if PAUSE in phones and len(phones) > 1:
            raise TableError(path, line, "pau cannot be combined with other phones")
        table[key] = tuple(phones)
    return table


def to_arpabet(mnemonic: str) -> tuple[str, ...] | None:
    """ARPAbet for an eSpeak mnemonic; unknown variants fall back to their base form.

    eSpeak marks allophones with suffixes (digits, ``#``, ``/``, ``-``); when a
    variant is missing from the table its base mnemonic is tried. ``None``
    means unknown even then: the caller absorbs the span into its neighbour.
    """
    table = espeak_map()
    name = mnemonic
    while name:
        if name in table:
            return table[name]
        stripped = name.rstrip("0123456789#/-")
        if stripped == name:
            break
        name = stripped
    return None


@cache
def _inherent_ms() -> dict[str, tuple[float, float]]:
    """(stressed, unstressed) inherent duration per bare phone, from durations.tsv."""
    from .durations import duration_table

    table = duration_table()
    return {p: (d.inherent_ms, d.unstressed_inherent_ms) for p, d in table.items()}


def inherent_ms(phone: str) -> float:
    if phone == PAUSE:
        return 200.0
    stressed, unstressed = _inherent_ms()[base(phone)]
    return unstressed if phone.endswith("0") else stressed


# --------------------------------------------------------------------------- fitting

def split_span(phones: Sequence[str], start: int, end: int) -> list[PhoneTiming]:
    """Share ``[start, end)`` among ``phones`` in proportion to their inherent durations.

    Boundaries are rounded cumulatively so the pieces tile the span exactly.
    """
    if not phones:
        return []
    weights = np.array([inherent_ms(p) for p in phones], dtype=float)
    edges = start + np.round(np.cumsum(weights) / weights.sum() * (end - start)).astype(int)
    bounds = [start, *edges[:-1].tolist(), end]
    return [(p, int(bounds[i]), int(bounds[i + 1])) for i, p in enumerate(phones)]


def fit_phones_in_words(words: Sequence[WordTiming], prons: Sequence[Sequence[str]],
                        num_samples: int) -> list[PhoneTiming]:
    """Phones for word-event-only engines: each word's phones fitted inside its span.

    ``words`` are measured ``(text, start, end)`` boundaries in order; ``prons``
    the ARPAbet phones lipclock's front end gives each word. Gaps between
    words (and before the first / after the last) become ``pau``.
    """
    if len(words) != len(prons):
        raise ValueError("one pronunciation per word is needed")
    out: list[PhoneTiming] = []
    cursor = 0
    for (_, start, end), pron in zip(words, prons, strict=True):
        start, end = max(start, cursor), max(end, start, cursor)
        if start > cursor:
            out.append((PAUSE, cursor, start))
        out.extend(split_span(list(pron), start, end))
        cursor = end
    if num_samples > cursor:
        out.append((PAUSE, cursor, num_samples))
    return [p for p in out if p[2] > p[1]]


# --------------------------------------------------------------------------- eSpeak path

def phones_from_events(events: Sequence[EngineEvent], num_samples: int) -> list[PhoneTiming]:
    """Contiguous ARPAbet phones from eSpeak phoneme events (each lasts until the next)."""
    marks = [(min(max(e.sample, 0), num_samples), e.name) for e in events
             if e.kind == "phoneme"]
    marks.sort(key=lambda m: m[0])  # stable: the engine's order is kept at equal samples
    out: list[PhoneTiming] = []
    if not marks or marks[0][0] > 0:
        out.append((PAUSE, 0, marks[0][0] if marks else num_samples))
    for i, (start, name) in enumerate(marks):
        end = marks[i + 1][0] if i + 1 < len(marks) else num_samples
        if end <= start:
            continue
        arpabet = to_arpabet(name)
        if not arpabet:  # absorbed ("-", or unknown): the previous phone runs on
            if out:
                out[-1] = (out[-1][0], out[-1][1], end)
            else:
                out.append((PAUSE, start, end))
            continue
        out.extend(split_span(arpabet, start, end))
    return _merge_pauses([p for p in out if p[2] > p[1]])


def _merge_pauses(phones: list[PhoneTiming]) -> list[PhoneTiming]:
    out: list[PhoneTiming] = []
    for p in phones:
        if out and p[0] == PAUSE and out[-1][0] == PAUSE:
            out[-1] = (PAUSE, out[-1][1], p[2])
        else:
            out.append(p)
    return out


def words_from_events(events: Sequence[EngineEvent], phones: Sequence[PhoneTiming]
                      ) -> list[WordTiming]:
    """Word spans: the first to the last spoken phone after each word event.

    eSpeak emits a word event a little before the word's first phoneme event
    (at the start of the preceding gap), so the span is taken from the phones
    themselves: word boundaries then coincide with phone boundaries.
    """
    starts = [(e.sample, e.name.lower()) for e in events if e.kind == "word" and e.name.strip()]
    out: list[WordTiming] = []
    for i, (start, text) in enumerate(starts):
        limit = starts[i + 1][0] if i + 1 < len(starts) else None
        spoken = [p for p in phones if p[0] != PAUSE and p[1] >= start
                  and (limit is None or p[1] < limit)]
        if spoken:
            out.append((text, spoken[0][1], spoken[-1][2]))
    return out


def _rescale(position: int, up: int, down: int) -> int:
    return (position * up + down // 2) // down


def _resample(samples: np.ndarray, native_rate: int, sample_rate: int) -> np.ndarray:
    if native_rate == sample_rate:
        return samples
    from scipy.signal import resample_poly

    g = gcd(native_rate, sample_rate)
    y = resample_poly(samples.astype(np.float64), sample_rate // g, native_rate // g)
    return np.clip(np.round(y), -32768, 32767).astype(np.int16)


# --------------------------------------------------------------------------- public API

@dataclass(frozen=True, slots=True)
class _Driver:
    name: str  # pyttsx3 driver module name: "espeak", "sapi5", "nsss", ...
    voice_ids: tuple[str, ...]


@cache
def _driver() -> _Driver | None:
    try:
        import pyttsx3
    except ImportError:
        return None
    try:
        engine = pyttsx3.init()
        voices = tuple(str(v.id) for v in engine.getProperty("voices"))
        module = type(engine.proxy._driver).__module__  # noqa: SLF001 - no public accessor
    except Exception:  # no engine on this machine: no system voices
        return None
    return _Driver(module.rsplit(".", 1)[-1], voices)


def system_voices() -> list[str]:
    """Voice ids pyttsx3 offers here (use as ``voice="system:<id>"``); [] without pyttsx3."""
    d = _driver()
    return list(d.voice_ids) if d else []


def synthesize_system(text: str, voice_id: str, sample_rate: int = 16000,
                      rate_wpm: int | None = None) -> SystemSpeech:
    """Speak ``text`` with system voice ``voice_id``; phones timed by the engine's events.

    Returns ``(samples, sample_rate, phones, words)``: int16 audio at
    ``sample_rate``; phones as contiguous ``(ARPAbet, start, end)`` sample
    spans; words as ``(text, start, end)``.
    """
    if voice_id.startswith(PREFIX):
        voice_id = voice_id[len(PREFIX):]
    if not text.strip():
        raise EmptyTextError("text is empty")
    if len(text) > MAX_TEXT_CHARS:
        raise TextTooLongError(len(text), MAX_TEXT_CHARS)
    if not 4000 <= sample_rate <= 96000:
        raise UnknownChoiceError("sample_rate", sample_rate,
                                 ["8000", "16000", "22050", "24000", "48000"])
    driver = _driver()
    if driver is None:
        raise SystemVoiceError("no system voices: pyttsx3 or its speech engine is missing")
    if voice_id not in driver.voice_ids:
        raise UnknownChoiceError("system voice", voice_id,
                                 [PREFIX + v for v in driver.voice_ids])
    if driver.name != "espeak":
        raise SystemVoiceError(
            f"pyttsx3 driver {driver.name!r} does not expose audio positions of its word "
            "events, so its phones cannot be timed (see docs/voices.md)")
    out = synthesize_events(text, voice_id, rate_wpm)
    n = len(out.samples)
    phones = phones_from_events(out.events, n)
    words = words_from_events(out.events, phones)
    samples = _resample(out.samples, out.sample_rate, sample_rate)
    phones, words = rescale_timings(phones, words, n, out.sample_rate, len(samples),
                                    sample_rate)
    return SystemSpeech(samples, sample_rate, phones, words)


def rescale_timings(phones: Sequence[PhoneTiming], words: Sequence[WordTiming],
                    num_samples: int, native_rate: int, new_num_samples: int,
                    sample_rate: int) -> tuple[list[PhoneTiming], list[WordTiming]]:
    """Move spans from the engine's clock to ``sample_rate`` (exact integer rounding).

    Every boundary goes through the same mapping, so contiguous phones stay
    contiguous; the end of the audio maps to the end of the resampled audio.
    """
    if native_rate == sample_rate:
        return list(phones), list(words)
    g = gcd(native_rate, sample_rate)
    up, down = sample_rate // g, native_rate // g

    def at(pos: int) -> int:
        return new_num_samples if pos >= num_samples else min(_rescale(pos, up, down),
                                                              new_num_samples)

    new_phones = [(p, at(s), at(e)) for p, s, e in phones]
    return ([p for p in new_phones if p[2] > p[1]], [(w, at(s), at(e)) for w, s, e in words])
