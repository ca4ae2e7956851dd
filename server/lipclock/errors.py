"""Typed errors raised at lipclock's input boundaries.

Every error carries a short machine-readable ``code`` and a human ``reason``.
The network layer maps them to 4xx responses / typed WebSocket error messages;
the CLI prints them without a traceback.
"""

from __future__ import annotations


class LipclockError(ValueError):
    """Base class: bad input that the caller can fix."""

    code = "bad_input"

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


class EmptyTextError(LipclockError):
    code = "empty_text"


class TextTooLongError(LipclockError):
    code = "text_too_long"

    def __init__(self, length: int, limit: int) -> None:
        super().__init__(f"text is {length} characters; the limit is {limit}")
        self.length = length
        self.limit = limit


class OutOfRangeError(LipclockError):
    """A numeric parameter outside its allowed range."""

    code = "out_of_range"

    def __init__(self, name: str, value: object, low: float, high: float) -> None:
        super().__init__(f"{name}={value!r} is out of range; allowed {low}..{high}")
        self.name = name
        self.low = low
        self.high = high


class UnknownChoiceError(LipclockError):
    """A name (voice, mouth model, format...) that is not one of the allowed values."""

    code = "unknown_choice"

    def __init__(self, name: str, value: object, allowed: list[str] | tuple[str, ...]) -> None:
        allowed_s = ", ".join(sorted(allowed))
        super().__init__(f"unknown {name} {value!r}; allowed: {allowed_s}")
        self.name = name
        self.allowed = tuple(allowed)


class TableError(LipclockError):
    """A data file (lexicon, phone targets, viseme table...) is malformed.

    The message always starts with ``file:line:`` so editors can jump to it.
    """

    code = "bad_table"

    def __init__(self, path: object, line: int, reason: str) -> None:
        super().__init__(f"{path}:{line}: {reason}")
        self.path = str(path)
        self.line = line
