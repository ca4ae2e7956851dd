"""Value types passed between the text stages: normalize -> pronounce -> prosody."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum


class BreakKind(StrEnum):
    """Phrase breaks produced by punctuation, weakest to strongest roughly."""

    COMMA = "comma"
    PAREN = "paren"  # opening or closing parenthesis
    DASH = "dash"
    COLON = "colon"
    SEMICOLON = "semicolon"
    ELLIPSIS = "ellipsis"
    PERIOD = "period"
    QUESTION = "question"
    EXCLAMATION = "exclamation"
    PARAGRAPH = "paragraph"  # blank line


@dataclass(frozen=True, slots=True)
class WordToken:
    """A word to be spoken. ``text`` is lowercase letters/apostrophes only."""

    text: str
    orth: str = ""  # the source text it came from, e.g. "$4.50" or "FBI"
    is_letter: bool = False  # a spelled-out letter ("f" in "FBI") -> letter name
    hint: str | None = None  # optional part-of-speech / homograph hint ("past", "noun"...)


@dataclass(frozen=True, slots=True)
class BreakToken:
    kind: BreakKind


Token = WordToken | BreakToken


@dataclass(frozen=True, slots=True)
class PronouncedWord:
    """A word with its phones (ARPAbet, stress digits on vowels)."""

    text: str
    phones: tuple[str, ...]
    orth: str = ""
    source: str = ""  # user | cmudict | lts | compound | letter | derived


Pronounced = PronouncedWord | BreakToken
