"""Phone-bigram blend curves (Xu, Feng, Marsella & Shapiro 2013, "A practical and
configurable lip sync method for games").

Phones are reduced to a 21-class common set (``bigram_classes.tsv``). For each
ordered class pair a set of pose-weight curves is stored as knots in normalised
time (``bigram_curves.tsv``; u = 0.5 is the phone boundary). For every adjacent
phone pair the curves are time-warped onto the real durations (each half maps
linearly onto one phone), and all pairs are stitched by taking the maximum per
pose. Then, per pose:

1. valley smoothing: dips narrower than ``valley_window_s`` between two peaks are
   filled (a grey-scale closing), so a pose does not flicker off and on; poses
   that win a constraint (closures) are exempt, or "mom" would lose its vowel;
2. pose-pair constraints with priorities (``bigram_constraints.tsv``): the
   winner's weight w caps the loser's at 1 - w;
3. a parametric speed limit: no weight changes faster than ``max_rate_per_s``;
   the limit widens peaks instead of cutting them, so closures are still reached.

The weighted mean of the pose targets (rest fills any missing weight) gives the
four articulatory measures, and ``shape.nodes_from_measures`` the node mesh.
Per-bigram hand-tuned curves (``bigram_overrides.tsv``) and per-character
override files (``bigram_characters/<name>.tsv``) replace the generated rows.
"""

from __future__ import annotations

import math
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from .. import _kernels
from ..errors import OutOfRangeError, TableError, UnknownChoiceError
from ..speech.phoneset import base, phones
from ..speech.timeline import Timeline
from ..tables import finite_float, iter_tsv, package_file
from .visemes import shapes

Curves = dict[tuple[str, str], dict[str, tuple[np.ndarray, np.ndarray]]]
BIGRAM_DEFAULTS: dict[str, float] = {"valley_window_s": 0.08, "max_rate_per_s": 14.0}
BIGRAM_RANGES: dict[str, tuple[float, float]] = {"valley_window_s": (0.0, 0.5),
                                                 "max_rate_per_s": (2.0, 200.0)}


def _table(name: str) -> Path:
    return package_file("lipclock.viseme_tables", name)


def load_classes(path: Path) -> dict[str, tuple[str, tuple[str, ...]]]:
    """class -> (pose, ARPAbet base phones). Every phone must be in exactly one class."""
    known_phones = {base(p) for p in phones()}
    poses = shapes()
    out: dict[str, tuple[str, tuple[str, ...]]] = {}
    seen: dict[str, str] = {}
    for line, f in iter_tsv(path):
        if len(f) != 3:
            raise TableError(path, line, f"expected 3 columns, got {len(f)}")
        cls, pose, members = f[0], f[1], tuple(f[2].split())
        if pose not in poses:
            raise TableError(path, line, f"unknown pose {pose!r}")
        for ph in members:
            if ph not in known_phones:
                raise TableError(path, line, f"unknown phone {ph!r}")
            if ph in seen:
                raise TableError(path, line, f"phone {ph!r} already in class {seen[ph]!r}")
            seen[ph] = cls
        out[cls] = (pose, members)
    missing = sorted(known_phones - set(seen))
    if missing:
        raise TableError(path, 1, f"phones without a class: {' '.join(missing)}")
    return out


def load_curves(path: Path, classes: dict[str, Any]) -> Curves:
    """(left, right) -> pose -> (u knots, weights). Knots must rise within 0..1."""
    poses = shapes()
    out: Curves = {}
    for line, f in iter_tsv(path):
        if len(f) != 4:
            raise TableError(path, line, f"expected 4 columns, got {len(f)}")
        left, right, pose, knots = f
        for c in (left, right):
            if c not in classes:
                raise TableError(path, line, f"unknown phone class {c!r}")
        if pose not in poses:
            raise TableError(path, line, f"unknown pose {pose!r}")
        us, ws = [], []
        for k in knots.split():
            u_s, sep, w_s = k.partition(":")
            if not sep:
                raise TableError(path, line, f"knot {k!r} is not u:weight")
            us.append(finite_float(path, line, "u", u_s))
            ws.append(finite_float(path, line, "weight", w_s))
        rising = all(b > a for a, b in zip(us, us[1:], strict=False))
        if not us or us[0] != 0.0 or us[-1] != 1.0 or not rising:
            raise TableError(path, line, "knots must rise strictly from u=0 to u=1")
        if any(not 0.0 <= w <= 1.0 for w in ws):
            raise TableError(path, line, "weights must be within 0..1")
        out.setdefault((left, right), {})[pose] = (np.array(us), np.array(ws))
    return out


def load_constraints(path: Path) -> list[tuple[str, str]]:
    poses = shapes()
    out = []
    for line, f in iter_tsv(path):
        if len(f) != 2:
            raise TableError(path, line, f"expected 2 columns, got {len(f)}")
        for p in f:
            if p not in poses:
                raise TableError(path, line, f"unknown pose {p!r}")
        out.append((f[0], f[1]))
    return out


@cache
def default_tables() -> tuple[dict[str, Any], Curves, list[tuple[str, str]]]:
    classes = load_classes(_table("bigram_classes.tsv"))
    curves = load_curves(_table("bigram_curves.tsv"), classes)
    missing = [f"{a}-{b}" for a in classes for b in classes if (a, b) not in curves]
    if missing:
        raise TableError(_table("bigram_curves.tsv"), 1,
                         f"{len(missing)} bigrams without curves, e.g. {missing[0]}; "
                         "run scripts/build_bigram_curves.py")
    overrides = _table("bigram_overrides.tsv")
    if overrides.exists():
        curves = {**curves, **load_curves(overrides, classes)}
    return classes, curves, load_constraints(_table("bigram_constraints.tsv"))


def _character_curves(name: str, classes: dict[str, Any], curves: Curves) -> Curves:
    folder = _table("bigram_characters")
    names = sorted(p.stem for p in folder.glob("*.tsv")) if folder.is_dir() else []
    if name not in names:
        raise UnknownChoiceError("bigram character", name, names or ["(none installed)"])
    return {**curves, **load_curves(folder / f"{name}.tsv", classes)}


_PACK_CACHE: dict[int, tuple[Curves, tuple[np.ndarray, ...]]] = {}


def _pack(keys: tuple[tuple[str, str], ...], curves: Curves,
          pose_names: tuple[str, ...]) -> tuple[np.ndarray, ...]:
    """Curves as padded arrays for the compiled stitcher: pose ids, knot u, knot w, counts."""
    hit = _PACK_CACHE.get(id(curves))
    if hit is not None and hit[0] is curves:  # only the long-lived default set is cached
        return hit[1]
    n_pose = max(len(curves[k]) for k in keys)
    n_knot = max(len(u) for k in keys for u, _ in curves[k].values())
    pose_id = np.full((len(keys), n_pose), -1, np.int64)
    ku = np.zeros((len(keys), n_pose, n_knot))
    kw = np.zeros((len(keys), n_pose, n_knot))
    nk = np.zeros((len(keys), n_pose), np.int64)
    for i, k in enumerate(keys):
        for j, (pose, (u, wt)) in enumerate(curves[k].items()):
            pose_id[i, j] = pose_names.index(pose)
            ku[i, j, :len(u)], kw[i, j, :len(u)], nk[i, j] = u, wt, len(u)
    if curves is default_tables()[1]:
        _PACK_CACHE[id(curves)] = (curves, (pose_id, ku, kw, nk))
    return pose_id, ku, kw, nk


def _stitch(fs: np.ndarray, bounds: np.ndarray, ids: np.ndarray, pose_id: np.ndarray,
            ku: np.ndarray, kw: np.ndarray, nk: np.ndarray, w: np.ndarray) -> None:
    """Time-warp each phone pair's curves onto its frames and stitch by maximum (in place).

    Pair i spans phones i and i+1: bounds[i]..bounds[i+2]; the left phone maps to
    u in [0, 0.5), the right one to [0.5, 1]. ``w`` is (n_poses, len(fs)) float64,
    C-contiguous; the packed curves come from ``_pack``. The loop is C (csrc/face.c).
    """
    f64, i64 = np.float64, np.int64
    if w.dtype != f64 or not w.flags.c_contiguous:
        raise ValueError("w must be a C-contiguous float64 array")
    _kernels.bigram_stitch(
        np.ascontiguousarray(fs, f64), np.ascontiguousarray(bounds, f64),
        np.ascontiguousarray(ids, i64), np.ascontiguousarray(pose_id, i64),
        np.ascontiguousarray(ku, f64), np.ascontiguousarray(kw, f64),
        np.ascontiguousarray(nk, i64), pose_id.shape[1], w)


def _closing(w: np.ndarray, width: int) -> np.ndarray:
    """Grey-scale closing (max filter then min filter): fills dips narrower than width."""
    if width < 2:
        return w
    pad = width // 2
    win = np.lib.stride_tricks.sliding_window_view
    d = win(np.pad(w, pad, mode="edge"), 2 * pad + 1).max(axis=1)
    return win(np.pad(d, pad, mode="edge"), 2 * pad + 1).min(axis=1)


def _speed_limit(w: np.ndarray, step: float) -> np.ndarray:
    """Slope-limited dilation: every weight >= neighbour - step, both directions."""
    w = np.array(w, dtype=np.float64)  # a fresh C-contiguous copy, limited in place
    _kernels.bigram_speed_limit(w, float(step))
    return w


def bigram_measures(timeline: Timeline, frame_samples: np.ndarray,
                    params: dict[str, Any] | None = None) -> np.ndarray:
    """(n_frames, 4) measures (lip_gap, width, protrusion, jaw; mm) at ``frame_samples``."""
    p = dict(BIGRAM_DEFAULTS)
    character = None
    for key, value in (params or {}).items():
        if key == "character":
            character = str(value)
            continue
        if key not in BIGRAM_RANGES:
            raise UnknownChoiceError("bigram parameter", key, [*BIGRAM_RANGES, "character"])
        lo, hi = BIGRAM_RANGES[key]
        v = float(value)
        if not (math.isfinite(v) and lo <= v <= hi):
            raise OutOfRangeError(key, value, lo, hi)
        p[key] = v
    classes, curves, constraints = default_tables()
    if character is not None:
        curves = _character_curves(character, classes, curves)
    cls_of = {ph: c for c, (_, members) in classes.items() for ph in members}
    pose_names = list(shapes())
    pose_index = {n: i for i, n in enumerate(pose_names)}
    fs = np.asarray(frame_samples, dtype=np.float64)
    w = np.zeros((len(pose_names), len(fs)))
    ph = timeline.phones
    keys = list(curves)
    key_id = {k: i for i, k in enumerate(keys)}
    pose_id, ku, kw, nk = _pack(tuple(keys), curves, tuple(pose_names))
    cls = [cls_of[base(p.phone)] for p in ph]
    ids = np.array([key_id[(a, b)] for a, b in zip(cls, cls[1:], strict=False)], np.int64)
    bounds = np.array([p.start for p in ph] + [ph[-1].end], dtype=np.float64)
    _stitch(fs, bounds, ids, pose_id, ku, kw, nk, w)
    if len(ph) == 1:
        w[pose_index[classes[cls_of[base(ph[0].phone)]][0]]] = 1.0
    frame_s = float(np.median(np.diff(fs))) / timeline.sample_rate if len(fs) > 1 else 0.01
    width = int(round(p["valley_window_s"] / frame_s))
    step = p["max_rate_per_s"] * frame_s
    winners = {pose_index[a] for a, _ in constraints}
    for i in range(len(pose_names)):
        # a pose that overrides others (closure) is not valley-filled: filling the
        # dip between two p/b/m would erase the vowel between them ("mom")
        if w[i].any() and i not in winners:
            w[i] = _closing(w[i], width)
    for winner, loser in constraints:
        wi, li = pose_index[winner], pose_index[loser]
        np.minimum(w[li], 1.0 - w[wi], out=w[li])
    for i in range(len(pose_names)):
        if w[i].any():
            w[i] = _speed_limit(w[i], step)
    for winner, loser in constraints:  # the speed limit may widen a loser: re-apply
        wi, li = pose_index[winner], pose_index[loser]
        np.minimum(w[li], 1.0 - w[wi], out=w[li])
    targets = np.array([shapes()[n].vector() for n in pose_names])  # (poses, 4)
    rest = pose_index["rest"]
    w[rest] = np.maximum(w[rest], 1.0 - w.sum(axis=0))
    return (w.T @ targets) / w.sum(axis=0)[:, None]
