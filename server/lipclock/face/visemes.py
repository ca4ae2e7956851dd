"""Visemes: phones -> viseme events on the sample clock (``viseme_tables/``).

The map keeps the DECface appendix distinctions that are visible: bilabial
closure, labiodental, dental, rounded/protruded, open, spread, r-coloured.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from ..errors import TableError
from ..speech.phoneset import phones, written_forms
from ..speech.timeline import Timeline
from ..tables import finite_float, iter_tsv, package_file

MEASURES = ("lip_gap_mm", "width_mm", "protrusion_mm", "jaw_mm")


@dataclass(frozen=True, slots=True)
class VisemeShape:
    name: str
    lip_gap_mm: float
    width_mm: float
    protrusion_mm: float
    jaw_mm: float

    def vector(self) -> tuple[float, float, float, float]:
        return (self.lip_gap_mm, self.width_mm, self.protrusion_mm, self.jaw_mm)


@dataclass(frozen=True, slots=True)
class VisemeEvent:
    viseme: str
    start: int
    end: int
    phone: str


def load_shapes(path: Path) -> dict[str, VisemeShape]:
    out: dict[str, VisemeShape] = {}
    for line, f in iter_tsv(path):
        if len(f) != 5:
            raise TableError(path, line, f"expected 5 columns, got {len(f)}")
        nums = [finite_float(path, line, m, v) for m, v in zip(MEASURES, f[1:], strict=True)]
        if nums[0] < 0 or nums[1] <= 0 or nums[3] < 0:
            raise TableError(path, line, "lip_gap and jaw must be >= 0, width > 0")
        if f[0] in out:
            raise TableError(path, line, f"duplicate viseme {f[0]!r}")
        out[f[0]] = VisemeShape(f[0], *nums)
    return out


def load_phone_map(path: Path, shapes: dict[str, VisemeShape]) -> dict[str, str]:
    known = phones()
    out: dict[str, str] = {}
    for line, f in iter_tsv(path):
        if len(f) != 2:
            raise TableError(path, line, f"expected 2 columns, got {len(f)}")
        ph, vis = f
        if ph not in known:
            raise TableError(path, line, f"unknown phone {ph!r}")
        if vis not in shapes:
            raise TableError(path, line, f"unknown viseme {vis!r}")
        out[ph] = vis
    missing = sorted(set(known) - set(out))
    if missing:
        raise TableError(path, 1, f"phones without a viseme: {' '.join(missing)}")
    return out


@cache
def shapes() -> dict[str, VisemeShape]:
    return load_shapes(package_file("lipclock.viseme_tables", "visemes.tsv"))


@cache
def phone_map() -> dict[str, str]:
    return load_phone_map(package_file("lipclock.viseme_tables", "phone_visemes.tsv"), shapes())


def load_viseme_nodes(path: Path, known: dict[str, VisemeShape]) -> dict[str, np.ndarray]:
    """``viseme node x y`` rows -> {viseme: (N_NODES, 2)}; every viseme gives every node."""
    from .shape import NODES

    index = {n: i for i, n in enumerate(NODES)}
    out: dict[str, np.ndarray] = {}
    seen: dict[str, set[str]] = {}
    first_line: dict[str, int] = {}
    for line, f in iter_tsv(path):
        if len(f) != 4:
            raise TableError(path, line, f"expected 4 columns, got {len(f)}")
        vis, node = f[0], f[1]
        if vis not in known:
            raise TableError(path, line, f"unknown viseme {vis!r}")
        if node not in index:
            raise TableError(path, line, f"unknown node {node!r}")
        if node in seen.setdefault(vis, set()):
            raise TableError(path, line, f"{vis}: node {node!r} given twice")
        x = finite_float(path, line, "x_mm", f[2])
        y = finite_float(path, line, "y_mm", f[3])
        arr = out.setdefault(vis, np.zeros((len(NODES), 2)))
        first_line.setdefault(vis, line)
        arr[index[node]] = (x, y)
        seen[vis].add(node)
    for vis in known:
        if vis not in out:
            raise TableError(path, 1, f"viseme {vis!r} has no node positions")
        missing = [n for n in NODES if n not in seen[vis]]
        if missing:
            raise TableError(path, first_line[vis], f"{vis}: missing nodes {', '.join(missing)}")
    return out


@cache
def viseme_nodes() -> dict[str, np.ndarray]:
    return load_viseme_nodes(package_file("lipclock.viseme_tables", "viseme_nodes.tsv"),
                             shapes())


@cache
def _viseme_by_phone() -> dict[str, str]:
    """phone_map() keyed by every phone string as written, stress digit included."""
    return {s: vis for ph, vis in phone_map().items() for s in written_forms(ph)}


def viseme_of(phone: str) -> str:
    vis = _viseme_by_phone().get(phone)
    return vis if vis is not None else phone_map()[phone.rstrip("012")]


def visemes_for(timeline: Timeline) -> tuple[VisemeEvent, ...]:
    """One event per phone, adjacent identical visemes merged."""
    by_phone = _viseme_by_phone()
    out: list[VisemeEvent] = []
    run: tuple[str, int, str] | None = None  # the open event: viseme, start, first phone
    end = 0
    for p in timeline.phones:
        v = by_phone.get(p.phone) or viseme_of(p.phone)
        if run is not None and run[0] == v:
            end = p.end
            continue
        if run is not None:
            out.append(VisemeEvent(run[0], run[1], end, run[2]))
        run, end = (v, p.start, p.phone), p.end
    if run is not None:
        out.append(VisemeEvent(run[0], run[1], end, run[2]))
    return tuple(out)
