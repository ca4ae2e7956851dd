"""Waters-style damped-spring mouth nodes, integrated on the audio clock.

Every node of the mouth mesh (face/shape.py) is a mass on a spring toward its
position in the current viseme, with velocity damping, plus elastic springs to
its mesh neighbours that pull toward the target's local shape (Waters &
Levergood 1993). Parameters per node group live in ``viseme_tables/dynamics.toml``.

Integration is semi-implicit Euler on a fixed step of whole audio samples
(never frame times). Bilabial and labiodental targets switch the lip nodes to a
stiffer, critically damped spring aimed past contact; a contact constraint
stops the inner lips from crossing, so they press together and close even in
fast speech, while other excursions shrink as the rate rises.
"""

from __future__ import annotations

import fnmatch
import math
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from .. import _kernels
from ..errors import LipclockError, OutOfRangeError, TableError, UnknownChoiceError
from ..speech.timeline import Timeline
from ..tables import finite_float, line_of, load_toml, package_file
from .shape import NODES
from .topology import topology
from .visemes import shapes, viseme_nodes, viseme_of

_LIP_PAIRS = [(NODES.index(f"inner_upper_{i}"), NODES.index(f"inner_lower_{i}"))
              for i in range(5)]
LIP_NODES = [i for i, n in enumerate(NODES) if n.startswith(("inner_", "outer_"))]
_INNER_UPPER = [NODES.index(f"inner_upper_{i}") for i in range(5)]
_INNER_LOWER = [NODES.index(f"inner_lower_{i}") for i in range(5)]




@dataclass(frozen=True)
class Dynamics:
    mass: np.ndarray  # (N,) kg
    stiffness: np.ndarray  # (N,) N/m
    damping: np.ndarray  # (N,) N*s/m
    closure_visemes: frozenset[str]
    closure_stiffness: float
    closure_damping: float
    overshoot_mm: float
    neighbour_stiffness: float
    step_s: float
    anticipation_s: float
    groups: dict[str, dict[str, float]]


PARAM_RANGES = {"mass": (1e-4, 10.0), "stiffness": (0.01, 1e5), "damping": (0.0, 1e4),
                "overshoot_mm": (0.0, 10.0), "step_s": (1e-4, 0.01),
                "anticipation_s": (0.0, 0.1)}


def load_dynamics(path: Path, overrides: dict[str, Any] | None = None) -> Dynamics:
    data = load_toml(path)
    groups = data.get("groups")
    if not isinstance(groups, dict) or not groups:
        raise TableError(path, 1, "missing [groups.*] tables")
    params = {f"{g}.{k}": v for g, t in groups.items() for k, v in t.items() if k != "nodes"}
    for section in ("closure", "neighbours", "integration"):
        if not isinstance(data.get(section), dict):
            raise TableError(path, 1, f"missing [{section}] table")
        params.update({f"{section}.{k}": v for k, v in data[section].items()
                       if k != "visemes"})
    for key, value in (overrides or {}).items():
        if key not in params:
            raise UnknownChoiceError("spring parameter", key, sorted(params))
        params[key] = value
    checked: dict[str, float] = {}
    for key, value in params.items():
        line = line_of(path, key.split(".")[-1])
        lo, hi = PARAM_RANGES[key.split(".")[-1]]
        if overrides and key in overrides:  # the caller's value: an out-of-range error
            try:
                v = float(value)
            except (TypeError, ValueError):
                raise OutOfRangeError(key, value, lo, hi) from None
            if not (math.isfinite(v) and lo <= v <= hi):
                raise OutOfRangeError(key, value, lo, hi)
            checked[key] = v
            continue
        v = finite_float(path, line, key, value)
        if not lo <= v <= hi:
            raise TableError(path, line, f"{key}={v} outside {lo}..{hi}")
        checked[key] = v
    mass, k, c = np.zeros(len(NODES)), np.zeros(len(NODES)), np.zeros(len(NODES))
    owner: dict[int, str] = {}
    for g, table in groups.items():
        line = line_of(path, f"[groups.{g}]")
        for pattern in table.get("nodes", []):
            hits = [i for i, n in enumerate(NODES) if fnmatch.fnmatch(n, pattern)]
            if not hits:
                raise TableError(path, line, f"group {g}: no node matches {pattern!r}")
            for i in hits:
                if i in owner:
                    raise TableError(path, line, f"node {NODES[i]} is in {owner[i]} and {g}")
                owner[i] = g
                mass[i], k[i], c[i] = (checked[f"{g}.mass"], checked[f"{g}.stiffness"],
                                       checked[f"{g}.damping"])
    missing = [NODES[i] for i in range(len(NODES)) if i not in owner]
    if missing:
        raise TableError(path, 1, f"nodes in no group: {', '.join(missing)}")
    vis = data["closure"].get("visemes", [])
    unknown = [v for v in vis if v not in shapes()]
    if unknown:
        raise TableError(path, line_of(path, "visemes"), f"unknown visemes {unknown}")
    return Dynamics(mass, k, c, frozenset(vis), checked["closure.stiffness"],
                    checked["closure.damping"], checked["closure.overshoot_mm"],
                    checked["neighbours.stiffness"], checked["integration.step_s"],
                    checked["integration.anticipation_s"],
                    {g: {k2: checked[f"{g}.{k2}"] for k2 in ("mass", "stiffness", "damping")}
                     for g in groups})


@cache
def default_dynamics() -> Dynamics:
    return load_dynamics(package_file("lipclock.viseme_tables", "dynamics.toml"))


def spring_params() -> dict[str, float]:
    """The constants a caller may override per utterance, keyed as in dynamics.toml."""
    d = default_dynamics()
    out = {f"{g}.{k}": v for g, t in d.groups.items() for k, v in t.items()}
    out.update({"closure.stiffness": d.closure_stiffness, "closure.damping": d.closure_damping,
                "closure.overshoot_mm": d.overshoot_mm,
                "neighbours.stiffness": d.neighbour_stiffness})
    return out


def check_spring_params(params: dict[str, Any]) -> None:
    """Typed errors for unknown keys, out-of-range values and unstable combinations."""
    d = load_dynamics(package_file("lipclock.viseme_tables", "dynamics.toml"), params)
    try:
        check_stability(d, d.step_s)
    except OutOfRangeError:
        limit = (0.5 / d.step_s) ** 2
        raise LipclockError(f"spring_params are unstable at the {d.step_s * 1000:g} ms "
                            f"integration step: every node's stiffness/mass (neighbour "
                            f"springs included) must stay below {limit:,.0f} s^-2; lower "
                            f"a stiffness or raise a mass") from None


def check_stability(d: Dynamics, dt: float) -> None:
    """Reject parameters whose stiffest node would make semi-implicit Euler unstable."""
    degree = np.bincount(topology().edges.ravel(), minlength=len(NODES))
    k_eff = d.stiffness + degree * d.neighbour_stiffness
    k_eff[LIP_NODES] = np.maximum(k_eff[LIP_NODES], d.closure_stiffness
                                  + degree[LIP_NODES] * d.neighbour_stiffness)
    omega = np.sqrt(k_eff / d.mass)
    worst = int(np.argmax(omega))
    if omega[worst] * dt >= 0.5:  # keep well inside the stable region (limit is 2)
        raise OutOfRangeError("integration.step_s", dt, PARAM_RANGES["step_s"][0],
                              round(0.5 / float(omega[worst]), 6))


def spring_nodes(timeline: Timeline, rate_hz: float, d: Dynamics) -> np.ndarray:
    """Node positions (n_frames, N, 2) at frames k*sample_rate/rate_hz of the timeline."""
    sr = timeline.sample_rate
    step = max(1, round(d.step_s * sr))
    dt = step / sr
    check_stability(d, dt)
    names = sorted(shapes())
    table = viseme_nodes()
    targets = np.stack([table[n] for n in names]).astype(np.float64)
    closure = np.array([n in d.closure_visemes for n in names])
    for v in np.flatnonzero(closure):  # aim past contact: the lips press together
        targets[v, _INNER_UPPER, 1] = targets[v, _INNER_UPPER, 1].mean() - 0.35 * d.overshoot_mm
        targets[v, _INNER_LOWER, 1] = targets[v, _INNER_UPPER, 1] + d.overshoot_mm
    rest = table["rest"].astype(np.float64)
    lead = round(d.anticipation_s * sr)
    n_steps = timeline.num_samples // step + 2
    starts = np.array([p.start for p in timeline.phones]) - lead
    pidx = np.clip(np.searchsorted(starts, np.arange(n_steps) * step, side="right") - 1, 0,
                   len(timeline.phones) - 1)
    index = {n: i for i, n in enumerate(names)}
    vis_idx = np.array([index[viseme_of(p.phone)] for p in timeline.phones])[pidx]
    lips = np.zeros(len(NODES), dtype=np.bool_)
    lips[LIP_NODES] = True
    n_frames = int(math.floor(timeline.num_samples * rate_hz / sr)) + 1
    frame_pos = np.round(np.arange(n_frames) * (sr / rate_hz)) / step  # in steps
    return _integrate(vis_idx, targets, closure, rest, d.mass, d.stiffness, d.damping,
                      d.closure_stiffness, d.closure_damping, lips, topology().edges,
                      d.neighbour_stiffness, np.array(_LIP_PAIRS, dtype=np.int64), dt,
                      frame_pos)


def _integrate(vis_idx: np.ndarray, targets: np.ndarray, closure: np.ndarray,
               rest: np.ndarray, mass: np.ndarray, k: np.ndarray, c: np.ndarray, k_cl: float,
               c_cl: float, lips: np.ndarray, edges: np.ndarray, k_nb: float,
               lip_pairs: np.ndarray, dt: float, frame_pos: np.ndarray) -> np.ndarray:
    """Step the mesh; record node positions at the first step at or after each frame
    (``frame_pos`` in steps; at most half a step, 1 ms, from the frame's sample).

    Shapes: vis_idx (n_steps,) viseme per step; targets (V, N, 2) mm; closure (V,) bool;
    rest (N, 2) mm; mass kg, k N/m, c N*s/m (N,); lips (N,) bool; edges (E, 2) and
    lip_pairs (P, 2, upper then lower) node indices; dt s. Returns (n_frames, N, 2) mm.
    The loop is C (csrc/face.c)."""
    f64, i64 = np.float64, np.int64
    rest = np.ascontiguousarray(rest, f64)
    out = np.empty((len(frame_pos), rest.shape[0], 2))
    _kernels.spring_integrate(
        np.ascontiguousarray(vis_idx, i64), np.ascontiguousarray(targets, f64),
        np.ascontiguousarray(closure, np.bool_), rest, np.ascontiguousarray(mass, f64),
        np.ascontiguousarray(k, f64), np.ascontiguousarray(c, f64), float(k_cl), float(c_cl),
        np.ascontiguousarray(lips, np.bool_), np.ascontiguousarray(edges, i64), float(k_nb),
        np.ascontiguousarray(lip_pairs, i64), float(dt), np.ascontiguousarray(frame_pos, f64),
        out)
    return out
