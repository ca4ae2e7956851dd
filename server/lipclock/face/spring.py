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
from numba import njit

from ..errors import OutOfRangeError, TableError, UnknownChoiceError
from ..speech.timeline import Timeline
from ..tables import finite_float, line_of, load_toml, package_file
from .shape import NODES, nodes_from_measures
from .visemes import shapes, viseme_of

_LIP_PAIRS = [(NODES.index(f"inner_upper_{i}"), NODES.index(f"inner_lower_{i}"))
              for i in range(5)]
LIP_NODES = [i for i, n in enumerate(NODES) if n.startswith(("inner_", "outer_"))]


def _edges() -> np.ndarray:
    e: list[tuple[str, str]] = []
    for part in ("outer_upper", "outer_lower", "inner_upper", "inner_lower"):
        chain = ["corner_l", *(f"{part}_{i}" for i in range(5)), "corner_r"]
        e += list(zip(chain, chain[1:], strict=False))
    for side in ("upper", "lower"):
        e += [(f"inner_{side}_{i}", f"outer_{side}_{i}") for i in range(5)]
    e += [("teeth_lower_l", "teeth_lower_c"), ("teeth_lower_c", "teeth_lower_r"),
          ("teeth_lower_c", "chin")]
    return np.array([(NODES.index(a), NODES.index(b)) for a, b in e], dtype=np.int64)


EDGES = _edges()


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


def check_stability(d: Dynamics, dt: float) -> None:
    """Reject parameters whose stiffest node would make semi-implicit Euler unstable."""
    degree = np.bincount(EDGES.ravel(), minlength=len(NODES))
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
    vec = np.array([shapes()[n].vector() for n in names])
    closure = np.array([n in d.closure_visemes for n in names])
    vec[closure, 0] = -d.overshoot_mm  # aim past contact
    targets = nodes_from_measures(vec).astype(np.float64)
    rest = nodes_from_measures(np.array([shapes()["rest"].vector()]))[0].astype(np.float64)
    lead = round(d.anticipation_s * sr)
    n_steps = timeline.num_samples // step + 2
    starts = np.array([p.start for p in timeline.phones]) - lead
    pidx = np.clip(np.searchsorted(starts, np.arange(n_steps) * step, side="right") - 1, 0,
                   len(timeline.phones) - 1)
    vis_idx = np.array([names.index(viseme_of(p.phone)) for p in timeline.phones])[pidx]
    lips = np.zeros(len(NODES), dtype=np.bool_)
    lips[LIP_NODES] = True
    n_frames = int(math.floor(timeline.num_samples * rate_hz / sr)) + 1
    frame_pos = np.round(np.arange(n_frames) * (sr / rate_hz)) / step  # in steps
    return _integrate(vis_idx, targets, closure, rest, d.mass, d.stiffness, d.damping,
                      d.closure_stiffness, d.closure_damping, lips, EDGES,
                      d.neighbour_stiffness, np.array(_LIP_PAIRS, dtype=np.int64), dt,
                      frame_pos)


@njit(cache=True, nogil=True)
def _integrate(vis_idx, targets, closure, rest, mass, k, c, k_cl, c_cl, lips, edges, k_nb,
               lip_pairs, dt, frame_pos):  # type: ignore[no-untyped-def]
    """Step the mesh; record node positions at the first step at or after each frame
    (``frame_pos`` in steps; at most half a step, 1 ms, from the frame's sample)."""
    n_steps = vis_idx.shape[0]
    n = rest.shape[0]
    out = np.empty((frame_pos.shape[0], n, 2))
    fi = 0
    x = rest.copy()
    v = np.zeros((n, 2))
    f = np.zeros((n, 2))
    for s in range(n_steps):
        vi = vis_idx[s]
        tgt = targets[vi]
        cl = closure[vi]
        for i in range(n):
            ki, ci = k[i], c[i]
            if cl and lips[i]:
                ki, ci = k_cl, c_cl
            for a in range(2):
                f[i, a] = ki * (tgt[i, a] - x[i, a]) - ci * v[i, a]
        for e in range(edges.shape[0]):
            i, j = edges[e, 0], edges[e, 1]
            for a in range(2):
                stretch = (x[j, a] - x[i, a]) - (tgt[j, a] - tgt[i, a])
                f[i, a] += k_nb * stretch
                f[j, a] -= k_nb * stretch
        for i in range(n):
            for a in range(2):
                v[i, a] += f[i, a] / mass[i] * dt
                x[i, a] += v[i, a] * dt
        for p in range(lip_pairs.shape[0]):  # the inner lips touch; they never cross
            u, lo = lip_pairs[p, 0], lip_pairs[p, 1]
            if x[lo, 1] > x[u, 1]:
                mid = 0.5 * (x[lo, 1] + x[u, 1])
                x[lo, 1] = mid
                x[u, 1] = mid
                vm = 0.5 * (v[lo, 1] + v[u, 1])
                v[lo, 1] = vm
                v[u, 1] = vm
        while fi < frame_pos.shape[0] and frame_pos[fi] <= s + 0.5:
            out[fi] = x
            fi += 1
    while fi < frame_pos.shape[0]:  # frames past the last step hold the final pose
        out[fi] = x
        fi += 1
    return out
