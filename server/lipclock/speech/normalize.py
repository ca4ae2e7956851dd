"""Text normalisation: raw text -> word and break tokens.

Numbers, abbreviations, acronyms, e-mail addresses and URLs are expanded into
words; punctuation becomes phrase breaks (speech/tokens.py BreakKind).
Unknown symbols are named when common (&, %, +, @) and dropped otherwise.
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Callable

from ..errors import EmptyTextError, TextTooLongError
from .tokens import BreakKind, BreakToken, Token, WordToken

ONES = ("zero one two three four five six seven eight nine ten eleven twelve thirteen "
        "fourteen fifteen sixteen seventeen eighteen nineteen").split()
TENS = "_ _ twenty thirty forty fifty sixty seventy eighty ninety".split()
SCALES = ((10**12, "trillion"), (10**9, "billion"), (10**6, "million"), (1000, "thousand"))
ORDINAL_IRREGULAR = {"one": "first", "two": "second", "three": "third", "five": "fifth",
                     "eight": "eighth", "nine": "ninth", "twelve": "twelfth"}
MAX_CARDINAL_DIGITS = 15

ABBREVIATIONS = {
    "mr": "mister", "mrs": "missus", "ms": "miz", "dr": "doctor", "prof": "professor",
    "st": "saint", "jr": "junior", "sr": "senior", "vs": "versus", "etc": "et cetera",
    "no": "number", "approx": "approximately", "dept": "department", "ave": "avenue",
    "mt": "mount", "ft": "feet", "lb": "pounds", "oz": "ounces", "jan": "january",
    "feb": "february", "aug": "august", "sept": "september", "oct": "october",
    "nov": "november", "dec": "december", "e.g": "for example", "i.e": "that is",
}
STREET_AFTER = {"st": "street", "dr": "drive"}
SYMBOLS = {"&": "and", "%": "percent", "+": "plus", "=": "equals", "@": "at", "#": "number",
           "°": "degrees", "×": "times"}
CURRENCY = {"$": ("dollar", "dollars", "cent", "cents"), "£": ("pound", "pounds", "penny", "pence"),
            "€": ("euro", "euros", "cent", "cents")}
BREAKS = {",": BreakKind.COMMA, ".": BreakKind.PERIOD, "?": BreakKind.QUESTION,
          "!": BreakKind.EXCLAMATION, ":": BreakKind.COLON, ";": BreakKind.SEMICOLON,
          "(": BreakKind.PAREN, ")": BreakKind.PAREN, "—": BreakKind.DASH, "–": BreakKind.DASH,
          "…": BreakKind.ELLIPSIS}

_TOKEN = re.compile(r"""
    (?P<email>[\w.+-]+@[\w-]+(?:\.[\w-]+)+)
  | (?P<url>(?:https?://|www\.)\S*[^\s.,;:!?)"'])
  | (?P<money>[$£€]\d+(?:,\d{3})*(?:\.\d+)?)
  | (?P<time>\d{1,2}:\d{2}(?:\s?[ap]\.?m\b\.?)?)
  | (?P<decade>\d{3}0s\b|'\d0s\b)
  | (?P<ordinal>\d+(?:st|nd|rd|th)\b)
  | (?P<number>(?:(?<![\w-])-)?\d+(?:,\d{3})*(?:\.\d+)?%?)
  | (?P<word>[^\W\d_](?:[^\W\d_]|['’](?=[^\W\d_]))*(?:\.(?!\.))?(?:[^\W\d_]\.(?!\.))*)
  | (?P<dash>\s-\s|--+|[—–])
  | (?P<ellipsis>\.\.\.+|…)
  | (?P<para>\n\s*\n)
  | (?P<punct>[,.?!:;()])
  | (?P<other>\S)
""", re.VERBOSE)


def say_cardinal(n: int) -> list[str]:
    if n < 0:
        return ["minus", *say_cardinal(-n)]
    if n < 20:
        return [ONES[n]]
    if n < 100:
        return [TENS[n // 10]] + ([ONES[n % 10]] if n % 10 else [])
    if n < 1000:
        return [ONES[n // 100], "hundred"] + (say_cardinal(n % 100) if n % 100 else [])
    for value, name in SCALES:
        if n >= value:
            rest = n % value
            return say_cardinal(n // value) + [name] + (say_cardinal(rest) if rest else [])
    return []


def say_digits(s: str) -> list[str]:
    return [ONES[int(c)] for c in s if c.isdigit()]


def say_year(n: int) -> list[str]:
    if 2000 <= n <= 2009:
        return say_cardinal(n)
    hi, lo = divmod(n, 100)
    if lo == 0:
        return say_cardinal(hi) + ["hundred"]
    return say_cardinal(hi) + (["oh"] + say_cardinal(lo) if lo < 10 else say_cardinal(lo))


def say_ordinal(n: int) -> list[str]:
    words = say_cardinal(n)
    last = words[-1]
    if last in ORDINAL_IRREGULAR:
        words[-1] = ORDINAL_IRREGULAR[last]
    elif last.endswith("y"):
        words[-1] = last[:-1] + "ieth"
    else:
        words[-1] = last + "th"
    return words


YEAR_CONTEXT = frozenset({"year", "in", "since", "until", "by", "of", "from", "to"})


def say_number(text: str, year_context: bool = False) -> list[str]:
    """Cardinal, decimal, negative, percentage; 4-digit numbers 1100-2099 read as years
    (1000-1099 too after words like "year" or "in")."""
    neg = text.startswith("-")
    body = text.lstrip("-").replace(",", "")
    pct = body.endswith("%")
    body = body.rstrip("%")
    whole, _, frac = body.partition(".")
    if len(whole) > MAX_CARDINAL_DIGITS:
        words = say_digits(whole)
    elif not frac and not pct and not neg and len(whole) == 4 and "," not in text and (
            1100 <= int(whole) <= 2099 or (year_context and 1000 <= int(whole) <= 2099)):
        words = say_year(int(whole))
    else:
        words = say_cardinal(int(whole or "0"))
    if frac:
        words += ["point", *say_digits(frac[:MAX_CARDINAL_DIGITS * 4])]
    if neg:
        words = ["minus", *words]
    if pct:
        words.append("percent")
    return words


def _spell(word: str, orth: str) -> list[Token]:
    return [WordToken(c, orth, is_letter=True) for c in word if "a" <= c <= "z"]


def _looks_pronounceable(word: str) -> bool:
    return bool(re.fullmatch(r"(?:[^aeiouy]{0,2}[aeiouy]+){1,}[^aeiouy]{0,2}", word))


def normalize(text: str, *, max_chars: int = 5000,
              is_word: Callable[[str], bool] | None = None) -> list[Token]:
    """Raw text -> tokens. Raises EmptyTextError / TextTooLongError."""
    if len(text) > max_chars:
        raise TextTooLongError(len(text), max_chars)
    if not text.strip():
        raise EmptyTextError("text is empty or only whitespace")
    text = unicodedata.normalize("NFKC", text)
    out: list[Token] = []
    prev_word = ""
    for m in _TOKEN.finditer(text):
        kind, s = m.lastgroup, m.group()
        toks: list[Token] = []
        ends_sentence = _ends_sentence(text, m.end())
        if kind == "email":
            user, _, domain = s.partition("@")
            toks = _read_parts(user, s) + [WordToken("at", s)] + _read_parts(domain, s)
        elif kind == "url":
            body = re.sub(r"^https?://", "", s).rstrip(".,;:!?)")
            toks = _read_parts(body, s)
        elif kind == "money":
            unit = CURRENCY[s[0]]
            whole, _, cents = s[1:].replace(",", "").partition(".")
            w = int(whole) if len(whole) <= MAX_CARDINAL_DIGITS else 0
            c = int(cents[:2].ljust(2, "0")) if cents else 0
            words = say_cardinal(w) + [unit[0] if w == 1 else unit[1]]
            if c and w == 0:
                words = say_cardinal(c) + [unit[2] if c == 1 else unit[3]]
            elif c:
                words += ["and", *say_cardinal(c), unit[2] if c == 1 else unit[3]]
            toks = [WordToken(x, s) for x in words]
        elif kind == "time":
            hh, mm = re.match(r"(\d+):(\d+)", s).groups()  # type: ignore[union-attr]
            words = say_cardinal(int(hh))
            if int(mm) == 0:
                words.append("o'clock") if not re.search("[ap]", s) else None
            else:
                words += (["oh"] + say_cardinal(int(mm))) if int(mm) < 10 else say_cardinal(int(mm))
            ampm = re.search(r"([ap])\.?m", s.lower())
            if ampm:
                words += [ampm.group(1), "m"]
            toks = [WordToken(x.replace("'", "") if x != "o'clock" else "o'clock", s,
                              is_letter=x in ("a", "p", "m") and bool(ampm)) for x in words]
            if s.endswith(".") and ends_sentence:
                toks.append(BreakToken(BreakKind.PERIOD))
        elif kind == "decade":
            digits = s.strip("'s")
            if len(digits) == 2:  # '90s
                words = say_cardinal(int(digits))
            elif digits.endswith("00"):
                words = say_cardinal(int(digits[:2])) + ["hundred"]
            else:
                words = say_year(int(digits))
            last = words[-1]
            words[-1] = last[:-1] + "ies" if last.endswith("y") else last + "s"
            toks = [WordToken(x, s) for x in words]
        elif kind == "ordinal":
            digits = s[:-2]
            words = say_ordinal(int(digits)) if len(digits) <= MAX_CARDINAL_DIGITS \
                else say_digits(digits)
            toks = [WordToken(x, s) for x in words]
        elif kind == "number":
            toks = [WordToken(x, s) for x in say_number(s, prev_word in YEAR_CONTEXT)]
        elif kind == "word":
            toks = _word(s, prev_word, is_word, _next_capitalised(text, m.end()), ends_sentence)
        elif kind == "dash":
            toks = [BreakToken(BreakKind.DASH)]
        elif kind == "ellipsis":
            toks = [BreakToken(BreakKind.ELLIPSIS)]
        elif kind == "para":
            toks = [BreakToken(BreakKind.PARAGRAPH)]
        elif kind == "punct":
            toks = [BreakToken(BREAKS[s])]
        elif s in SYMBOLS:
            toks = [WordToken(x, s) for x in SYMBOLS[s].split()]
        elif s in BREAKS:
            toks = [BreakToken(BREAKS[s])]
        out.extend(toks)
        if toks and isinstance(toks[-1], WordToken):
            prev_word = toks[-1].text
    if not any(isinstance(t, WordToken) for t in out):
        raise EmptyTextError("text has nothing speakable (only symbols or punctuation)")
    return out


MAX_WORD_LETTERS = 40


def _ends_sentence(text: str, end: int) -> bool:
    """After an abbreviation's period: end of text, or a capitalised word follows."""
    rest = text[end:end + 40].lstrip()
    return not rest or rest[0].isupper() or rest[0] in "\n"


def _next_capitalised(text: str, end: int) -> bool:
    rest = text[end:end + 40].lstrip(" \t")
    return bool(rest) and rest[0].isupper()


def _word(s: str, prev: str, is_word: Callable[[str], bool] | None, next_cap: bool = False,
          ends_sentence: bool = False) -> list[Token]:
    trailing_period = s.endswith(".") and s.count(".") == 1
    core = s[:-1] if trailing_period else s
    ascii_core = unicodedata.normalize("NFKD", core).encode("ascii", "ignore").decode()
    ascii_core = ascii_core.replace("’", "'")
    low = ascii_core.lower()
    toks: list[Token] = []
    if not low:
        return [BreakToken(BreakKind.PERIOD)] if trailing_period else []
    if "." in low:  # e.g. / i.e. / U.S.
        key = low.rstrip(".")
        if key in ABBREVIATIONS:
            toks = [WordToken(x, s) for x in ABBREVIATIONS[key].split()]
        else:
            toks = _spell(low.replace(".", ""), s)
        if s.endswith(".") and ends_sentence and key not in ("e.g", "i.e"):
            toks.append(BreakToken(BreakKind.PERIOD))
        return toks
    if trailing_period and low in ABBREVIATIONS:
        if low in STREET_AFTER and not next_cap:
            # "Elm Dr." / "Mary St.": a street when no name follows
            toks = [WordToken(x, s) for x in STREET_AFTER[low].split()]
            if ends_sentence:
                toks.append(BreakToken(BreakKind.PERIOD))
            return toks
        toks = [WordToken(x, s) for x in ABBREVIATIONS[low].split()]
        title = low in ("mr", "mrs", "ms", "dr", "prof", "st", "mt", "no")
        if ends_sentence and not (title and next_cap):
            toks.append(BreakToken(BreakKind.PERIOD))
        return toks
    if ascii_core.isupper() and len(ascii_core) > 1 and "'" not in ascii_core:
        known = is_word(low) if is_word else False
        if (known and len(low) > 3) or (not known and len(low) > 3 and _looks_pronounceable(low)):
            toks = [WordToken(low, s)]
        elif len(low) <= 6:
            toks = _spell(low, s)
        else:
            toks = [WordToken(low[:MAX_WORD_LETTERS], s)]
    elif len(low) > MAX_WORD_LETTERS:
        toks = [WordToken(low[i:i + MAX_WORD_LETTERS], s)
                for i in range(0, min(len(low), 400), MAX_WORD_LETTERS)]
    else:
        toks = [WordToken(low.strip("'"), s)] if low.strip("'") else []
    if trailing_period:
        toks.append(BreakToken(BreakKind.PERIOD))
    return toks


def _read_parts(s: str, orth: str) -> list[Token]:
    out: list[Token] = []
    for piece in re.split(r"([./_\-:])", s):
        if not piece:
            continue
        if piece == ".":
            out.append(WordToken("dot", orth))
        elif piece == "/":
            out.append(WordToken("slash", orth))
        elif piece in "_-:":
            out.append(WordToken({"_": "underscore", "-": "dash", ":": "colon"}[piece], orth))
        elif piece.isdigit():
            out.extend(WordToken(x, orth) for x in say_number(piece[:MAX_CARDINAL_DIGITS]))
        elif piece.lower() == "www":
            out.extend(_spell("www", orth))
        else:
            low = re.sub("[^a-z']", "", piece.lower())[:MAX_WORD_LETTERS]
            if low:
                out.append(WordToken(low, orth))
    return out


def tokens_to_text(tokens: list[Token]) -> str:
    """Canonical rendering for golden files: words, letters as ``f.``, breaks as ``<comma>``."""
    parts = []
    for t in tokens:
        if isinstance(t, BreakToken):
            parts.append(f"<{t.kind.value}>")
        elif t.is_letter:
            parts.append(f"{t.text}.")
        else:
            parts.append(t.text)
    return " ".join(parts)
