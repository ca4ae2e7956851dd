"""Phrasing: pronounced words and breaks -> phrases, each labelled with how it ends.

Punctuation breaks end phrases; the break decides the phrase's final F0 movement
(statement fall, yes/no rise, wh-question fall, continuation rise) and the pause
after it. When two breaks meet ("word ,.") the stronger one wins.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from .timeline import PhraseKind
from .tokens import BreakKind, BreakToken, Pronounced, PronouncedWord

WH_WORDS = frozenset({"who", "what", "when", "where", "why", "how", "which", "whose", "whom"})


@dataclass(frozen=True, slots=True)
class Phrase:
    words: tuple[PronouncedWord, ...]
    end: BreakKind | None  # the break after the phrase (None: end of text)
    kind: PhraseKind


_CONTINUATION = {BreakKind.COMMA, BreakKind.PAREN, BreakKind.DASH, BreakKind.COLON,
                 BreakKind.SEMICOLON}
_SENTENCE_END = {BreakKind.PERIOD, BreakKind.QUESTION, BreakKind.EXCLAMATION,
                 BreakKind.PARAGRAPH, BreakKind.ELLIPSIS}


def split_phrases(items: Sequence[Pronounced]) -> list[Phrase]:
    """Group words between breaks; label each phrase with how it ends."""
    phrases: list[Phrase] = []
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
            phrases.append(Phrase(tuple(current), end, _phrase_kind(end, sentence_first)))
            current = []
        elif phrases and end is not None and _strength(end) > _strength(phrases[-1].end):
            last = phrases[-1]  # "word ,." -> keep the stronger break
            phrases[-1] = Phrase(last.words, end, _phrase_kind(end, sentence_first))
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


def pause_s(end: BreakKind | None, comma_pause_s: float, period_pause_s: float) -> float:
    """Silence after a phrase ending in ``end``, from the caller's comma and period pauses."""
    if end is None:
        return 0.0
    if end in (BreakKind.COMMA, BreakKind.PAREN, BreakKind.DASH):
        return comma_pause_s
    if end in (BreakKind.COLON, BreakKind.SEMICOLON):
        return 0.5 * (comma_pause_s + period_pause_s)
    if end is BreakKind.PARAGRAPH:
        return 1.5 * period_pause_s
    return period_pause_s
