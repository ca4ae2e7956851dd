"""Per-phone Klatt targets: the table ``data/klatt_targets.tsv`` and its reading.

Each row is a phone's steady-state aim (formants, bandwidths, source and parallel
amplitudes; a second formant target for diphthongs). The rules that turn a
sequence of targets into speech are in tracks.py.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from ..errors import TableError
from ..tables import finite_float, iter_tsv, package_file
from .phoneset import PAUSE, phones

COLS = ("F1", "F2", "F3", "B1", "B2", "B3", "AV", "AF", "AH", "A2", "A3", "A4", "A5", "A6",
        "AB", "FNZ")
# the fields a Target carries as start/end vectors, blended by the transition rules
FORMANT_FIELDS = ("F1", "F2", "F3", "B1", "B2", "B3", "FNZ")
FORMANT_FIELDS_N = len(FORMANT_FIELDS)


@dataclass(frozen=True, slots=True)
class Target:
    phone: str
    values: dict[str, float]
    start: np.ndarray  # (7,) F1 F2 F3 B1 B2 B3 FNZ at the start
    end: np.ndarray  # same at the end (differs for diphthongs)


def load_targets(path: Path) -> dict[str, Target]:
    """Read a targets table; any bad row raises TableError naming its file and line."""
    known = set(phones()) - {PAUSE} | {"AX"}
    out: dict[str, Target] = {}
    for line, fields in iter_tsv(path):
        name = fields[0]
        if name not in known:
            raise TableError(path, line, f"unknown phone {name!r}")
        if len(fields) not in (len(COLS) + 1, len(COLS) + 4):
            raise TableError(path, line, f"expected {len(COLS) + 1} or {len(COLS) + 4} columns, "
                                         f"got {len(fields)}")
        nums = [finite_float(path, line, c, v) for c, v in zip(COLS, fields[1:], strict=False)]
        vals = dict(zip(COLS, nums, strict=True))
        start = np.array([vals[f] for f in FORMANT_FIELDS])
        end = start.copy()
        if len(fields) == len(COLS) + 4:
            end[:3] = [finite_float(path, line, "F*b", v) for v in fields[len(COLS) + 1:]]
        if np.any(start[:6] <= 0) or np.any(end[:3] <= 0):
            raise TableError(path, line, "formants and bandwidths must be positive")
        out[name] = Target(name, vals, start, end)
    missing = sorted(known - set(out))
    if missing:
        raise TableError(path, 1, f"no targets for: {' '.join(missing)}")
    return out


@cache
def targets() -> dict[str, Target]:
    """The packaged table, read once."""
    return load_targets(package_file("lipclock.speech", "data/klatt_targets.tsv"))


def target_for(phone: str) -> Target:
    """The target of a phone string as written: AH0 is schwa (the AX row), and other
    unstressed vowels except the tense/r-coloured ones are reduced 30% toward it."""
    t = targets()
    b = phone.rstrip("012")
    if b == "AH" and phone.endswith("0"):
        return t["AX"]
    tgt = t[b]
    if phone.endswith("0") and b not in ("ER", "IY", "IH", "UW", "OW"):
        ax = t["AX"]  # reduce unstressed vowels 30% toward schwa
        return Target(tgt.phone, tgt.values, 0.7 * tgt.start + 0.3 * ax.start,
                      0.7 * tgt.end + 0.3 * ax.end)
    return tgt
