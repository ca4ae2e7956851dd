"""Helpers for loading data tables (TSV and TOML) with ``file:line`` errors.

Tables are data, validated when loaded (DESIGN.md principle 4). TOML parse
errors from :mod:`tomllib` carry a line number already; semantic errors found
after parsing are located by searching the source for the offending key.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Iterator
from importlib import resources
from pathlib import Path
from typing import Any

from .errors import TableError


def package_file(package: str, name: str) -> Path:
    """Path of a data file shipped inside a package (works for wheels and editable installs)."""
    return Path(str(resources.files(package).joinpath(name)))


def iter_tsv(path: Path) -> Iterator[tuple[int, list[str]]]:
    """Yield ``(line_number, fields)`` for each data row of a TSV file.

    ``#`` starts a comment (whole-line or trailing); blank lines are skipped.
    """
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise TableError(path, 1, f"not UTF-8: {exc}") from None
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].rstrip()
        if not line.strip():
            continue
        yield number, [f.strip() for f in line.split("\t")]


def load_toml(path: Path) -> dict[str, Any]:
    """Parse a TOML file, turning syntax errors into :class:`TableError` with the line."""
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        line = getattr(exc, "lineno", None) or _line_from_message(str(exc))
        raise TableError(path, line, f"TOML syntax: {exc}") from None


def _line_from_message(message: str) -> int:
    marker = "line "
    if marker in message:
        tail = message.rsplit(marker, 1)[1]
        digits = "".join(ch for ch in tail if ch.isdigit())
        if digits:
            return int(digits)
    return 1


def line_of(path: Path, needle: str, default: int = 1) -> int:
    """1-based number of the first line of ``path`` containing ``needle`` (for error messages)."""
    try:
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            if needle in line:
                return number
    except OSError:
        pass
    return default


def finite_float(path: Path, line: int, name: str, value: object) -> float:
    """Convert to float, rejecting NaN/inf and non-numbers with a located error."""
    try:
        result = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise TableError(path, line, f"{name}: expected a number, got {value!r}") from None
    if not math.isfinite(result):
        raise TableError(path, line, f"{name}: value must be finite, got {value!r}")
    return result
