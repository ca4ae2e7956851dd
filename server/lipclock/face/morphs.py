"""The viseme -> 3-D morph-target table (``viseme_tables/morphs.tsv``), checked on the server.

The browser adaptor ``client/morphs.js`` reads the same file (served at
``/tables/morphs.tsv``) to drive the Oculus viseme morph targets of a 3-D avatar. Rows are
keyed by one of our viseme classes or, to override its class, by one phone; the value is an
Oculus viseme morph name as avatars spell it. This module validates the table with
``file:line`` errors before the server hands it out, so a bad edit fails loudly here rather
than as odd mouths in a browser.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

from ..errors import TableError
from ..speech.phoneset import phones
from ..tables import iter_tsv, package_file
from .exports import OCULUS
from .visemes import phone_map, shapes

# Oculus ih/oh/ou are spelt viseme_I/O/U by the avatars that carry these morphs.
_SPELLING = {"ih": "I", "oh": "O", "ou": "U"}
OCULUS_MORPHS = tuple(f"viseme_{_SPELLING.get(v, v)}" for v in OCULUS)


def load_morph_table(path: Path, classes: set[str], known_phones: set[str]) -> dict[str, str]:
    """``key morph`` rows -> {viseme class or phone: Oculus morph}; every class needs a row."""
    out: dict[str, str] = {}
    for line, f in iter_tsv(path):
        if len(f) != 2:
            raise TableError(path, line, f"expected 2 columns (key, morph), got {len(f)}")
        key, morph = f
        if key not in classes and key not in known_phones:
            raise TableError(path, line, f"{key!r} is neither a viseme class nor a phone")
        if morph not in OCULUS_MORPHS:
            raise TableError(path, line, f"unknown morph {morph!r}; expected one of "
                                         f"{' '.join(OCULUS_MORPHS)}")
        if key in out:
            raise TableError(path, line, f"{key!r} is given twice")
        out[key] = morph
    missing = sorted(classes - set(out))
    if missing:
        raise TableError(path, 1, f"viseme classes without a morph: {' '.join(missing)}")
    return out


def morph_table_path() -> Path:
    return package_file("lipclock.viseme_tables", "morphs.tsv")


@cache
def morph_table() -> dict[str, str]:
    return load_morph_table(morph_table_path(), set(shapes()), set(phones()))


def morph_of(phone: str) -> str:
    """The Oculus morph the browser adaptor shows for a phone (stress digits ignored)."""
    base = phone.rstrip("012")
    table = morph_table()
    return table.get(base) or table[phone_map()[base]]
