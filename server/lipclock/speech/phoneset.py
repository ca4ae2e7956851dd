"""The phone set shared by every stage (ARPAbet + ``pau``), loaded from ``data/phones.tsv``.

Phone strings in lipclock are ARPAbet as in CMUdict: vowels carry a stress
digit (``AH0``, ``IY1``), consonants do not; ``pau`` is silence.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path

from ..errors import TableError
from ..tables import iter_tsv, package_file

CLASSES = frozenset(
    {"vowel", "diphthong", "stop", "fricative", "affricate", "nasal", "liquid", "glide",
     "aspirate", "silence"}
)
PAUSE = "pau"
# A phone string is a phone name plus at most one stress digit (vowels need one).
STRESS_MARKS = ("", "0", "1", "2")


@dataclass(frozen=True, slots=True)
class PhoneInfo:
    name: str
    cls: str
    voiced: bool
    place: str

    @property
    def is_vowel(self) -> bool:
        return self.cls in ("vowel", "diphthong")

    @property
    def is_consonant(self) -> bool:
        return not self.is_vowel and self.cls != "silence"


@cache
def phones() -> dict[str, PhoneInfo]:
    """All phones by bare name (no stress digit)."""
    return load_phoneset(package_file("lipclock.speech", "data/phones.tsv"))


def load_phoneset(path: Path) -> dict[str, PhoneInfo]:
    table: dict[str, PhoneInfo] = {}
    for line, fields in iter_tsv(path):
        if len(fields) < 4:
            raise TableError(path, line, f"expected at least 4 columns, got {len(fields)}")
        name, cls, voiced, place = fields[:4]
        if cls not in CLASSES:
            raise TableError(path, line, f"unknown class {cls!r}")
        if voiced not in ("0", "1"):
            raise TableError(path, line, f"voiced must be 0 or 1, got {voiced!r}")
        if name in table:
            raise TableError(path, line, f"duplicate phone {name!r}")
        table[name] = PhoneInfo(name, cls, voiced == "1", place)
    return table


def base(phone: str) -> str:
    """``"AH0"`` -> ``"AH"``; consonants and ``pau`` unchanged."""
    return phone[:-1] if phone and phone[-1].isdigit() else phone


def stress(phone: str) -> int | None:
    """Stress digit of a vowel phone string, or ``None`` for consonants and pauses."""
    return int(phone[-1]) if phone and phone[-1].isdigit() else None


def info(phone: str) -> PhoneInfo:
    """Features of a phone string (stress digit allowed). Raises KeyError if unknown."""
    hit = _info_by_string().get(phone)
    return hit if hit is not None else phones()[base(phone)]


@cache
def _info_by_string() -> dict[str, PhoneInfo]:
    """phones() keyed by every phone string as written (tracks.py asks per phone)."""
    return {s: p for name, p in phones().items() for s in written_forms(name)}


def written_forms(name: str) -> tuple[str, ...]:
    """Every way phone ``name`` can be written in a phone string: bare or with a stress
    digit. Tables keyed by phone string (as written in timelines) are built from this."""
    return tuple(name + mark for mark in STRESS_MARKS)


def is_valid(phone: str) -> bool:
    """True for a known phone with a stress digit iff it is a vowel."""
    b = base(phone)
    p = phones().get(b)
    if p is None:
        return False
    has_digit = phone != b
    if p.is_vowel:
        return has_digit and phone[-1] in "012"
    return not has_digit
