"""Mouth motion models: viseme targets -> node trajectories on the audio clock.

* ``linear`` / ``cosine``: interpolation between viseme targets placed at phone
  centres (the DECface baselines; Waters & Levergood 1993).
* ``spring``: Waters-style damped springs. Each articulatory measure (lip gap,
  width, protrusion, jaw) is a mass on a spring toward the current viseme
  target with velocity damping, integrated with semi-implicit Euler on a fixed
  step of whole audio samples (never frame times). Closure visemes (bilabial,
  labiodental) use a stiffer, critically damped spring and a target slightly
  past contact (lips compress), so closure is reached even in fast speech;
  otherwise excursions shrink as the speaking rate rises, as the DECface report
  describes. Targets lead the acoustic phone by ``anticipation_s``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from ..errors import OutOfRangeError, UnknownChoiceError
from ..speech.timeline import Timeline
from .shape import LOWER_LIP_MID, NODES, UPPER_LIP_MID, nodes_from_measures
from .track import MouthTrack
from .visemes import shapes, viseme_of

MOUTH_MODELS = ("linear", "cosine", "spring")
CLOSURE_VISEMES = frozenset({"closed", "labiodental"})

SPRING_DEFAULTS: dict[str, float] = {
    "lip_hz": 5.0,  # natural frequency of the lip/jaw springs
    "lip_damping": 0.85,  # damping ratio (1 = critical)
    "closure_hz": 14.0,  # stiffer spring for bilabial / labiodental targets
    "closure_damping": 1.0,
    "jaw_hz": 4.0,
    "jaw_damping": 1.0,
    "step_s": 0.001,  # integration step, rounded to whole samples
    "anticipation_s": 0.02,
    "closure_overshoot_mm": 4.0,
}
PARAM_RANGES: dict[str, tuple[float, float]] = {
    "lip_hz": (0.5, 40.0), "lip_damping": (0.05, 4.0), "closure_hz": (0.5, 60.0),
    "closure_damping": (0.05, 4.0), "jaw_hz": (0.5, 40.0), "jaw_damping": (0.05, 4.0),
    "step_s": (1e-4, 0.01), "anticipation_s": (0.0, 0.1), "closure_overshoot_mm": (0.0, 10.0),
}


def _targets(timeline: Timeline) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Per phone: centre sample, target measures (n, 4), viseme names."""
    sh = shapes()
    centres, vecs, names = [], [], []
    for p in timeline.phones:
        v = viseme_of(p.phone)
        vec = list(sh[v].vector())
        if p.phone == "AH0":
            vec[0] *= 0.6  # schwa: smaller opening
            vec[3] *= 0.6
        centres.append((p.start + p.end) // 2)
        vecs.append(vec)
        names.append(v)
    return np.array(centres, dtype=np.float64), np.array(vecs, dtype=np.float64), names


def _measures(m: np.ndarray, nodes: np.ndarray) -> dict[str, np.ndarray]:
    gap = nodes[:, UPPER_LIP_MID, 1] - nodes[:, LOWER_LIP_MID, 1]
    width = nodes[:, 1, 0] - nodes[:, 0, 0]
    return {"lip_gap": gap.astype(np.float32), "width": width.astype(np.float32),
            "jaw": m[:, 3].astype(np.float32)}


def _track(timeline: Timeline, rate_hz: float, model: str, m: np.ndarray) -> MouthTrack:
    m[:, 0] = np.maximum(m[:, 0], 0.0)
    m[:, 3] = np.maximum(m[:, 3], 0.0)
    nodes = nodes_from_measures(m)
    return MouthTrack(timeline.sample_rate, rate_hz, model, NODES, nodes, _measures(m, nodes))


def _frame_samples(timeline: Timeline, rate_hz: float) -> np.ndarray:
    n = int(math.floor(timeline.num_samples * rate_hz / timeline.sample_rate)) + 1
    return np.round(np.arange(n) * (timeline.sample_rate / rate_hz))


def _interp(timeline: Timeline, rate_hz: float, cosine: bool) -> np.ndarray:
    centres, vecs, _ = _targets(timeline)
    fs = _frame_samples(timeline, rate_hz)
    idx = np.clip(np.searchsorted(centres, fs, side="right") - 1, 0, len(centres) - 1)
    nxt = np.minimum(idx + 1, len(centres) - 1)
    span = np.maximum(centres[nxt] - centres[idx], 1.0)
    u = np.clip((fs - centres[idx]) / span, 0.0, 1.0)
    if cosine:
        u = 0.5 - 0.5 * np.cos(np.pi * u)
    return vecs[idx] + (vecs[nxt] - vecs[idx]) * u[:, None]


def _spring(timeline: Timeline, rate_hz: float, params: dict[str, float]) -> np.ndarray:
    sr = timeline.sample_rate
    step = max(1, round(params["step_s"] * sr))
    dt = step / sr
    for key in ("lip_hz", "closure_hz", "jaw_hz"):
        w = 2 * math.pi * params[key]
        if w * dt >= 0.5:  # semi-implicit Euler: keep well inside the stable region
            raise OutOfRangeError(key, params[key], PARAM_RANGES[key][0],
                                  round(0.5 / (2 * math.pi * dt), 2))
    sh = shapes()
    rest = np.array(sh["rest"].vector())
    lead = round(params["anticipation_s"] * sr)
    n_steps = timeline.num_samples // step + 2
    tgt = np.empty((n_steps, 4))
    closure = np.zeros(n_steps, dtype=bool)
    step_samples = np.arange(n_steps) * step
    starts = np.array([p.start for p in timeline.phones]) - lead
    pidx = np.clip(np.searchsorted(starts, step_samples, side="right") - 1, 0,
                   len(timeline.phones) - 1)
    _, vecs, names = _targets(timeline)
    tgt[:] = vecs[pidx]
    closure[:] = np.array([n in CLOSURE_VISEMES for n in names])[pidx]
    tgt[closure, 0] -= params["closure_overshoot_mm"]
    w = np.array([2 * math.pi * params["lip_hz"], 2 * math.pi * params["jaw_hz"],
                  2 * math.pi * params["closure_hz"]])
    z = np.array([params["lip_damping"], params["jaw_damping"], params["closure_damping"]])
    out = _integrate(tgt, closure, rest, w, z, dt)
    fs = _frame_samples(timeline, rate_hz)
    pos = fs / step
    k = np.clip(pos.astype(np.int64), 0, n_steps - 2)
    frac = (pos - k)[:, None]
    return out[k] * (1 - frac) + out[k + 1] * frac


@njit(cache=True, nogil=True)
def _integrate(tgt: np.ndarray, closure: np.ndarray, rest: np.ndarray, w: np.ndarray,
               z: np.ndarray, dt: float) -> np.ndarray:
    """Semi-implicit Euler over fixed steps. Measures: lip gap, width, protrusion, jaw.

    w/z: natural frequency (rad/s) and damping ratio for lips, jaw and closure.
    The lip gap uses the closure spring while a closure viseme is the target and
    cannot go below contact (the lips press together instead).
    """
    n = tgt.shape[0]
    out = np.empty((n, 4))
    x = rest.copy()
    v = np.zeros(4)
    for i in range(n):
        for j in range(4):
            if j == 3:
                wj, zj = w[1], z[1]
            elif j == 0 and closure[i]:
                wj, zj = w[2], z[2]
            else:
                wj, zj = w[0], z[0]
            a = wj * wj * (tgt[i, j] - x[j]) - 2.0 * zj * wj * v[j]
            v[j] += a * dt
            x[j] += v[j] * dt
        if x[0] < 0.0:
            x[0] = 0.0
            if v[0] < 0.0:
                v[0] = 0.0
        out[i] = x
    return out


def mouth_for(timeline: Timeline, model: str = "spring", rate_hz: float = 100.0,
              params: dict[str, Any] | None = None) -> MouthTrack:
    if model not in MOUTH_MODELS:
        raise UnknownChoiceError("mouth_model", model, MOUTH_MODELS)
    if not (1.0 <= rate_hz <= 1000.0):
        raise OutOfRangeError("rate_hz", rate_hz, 1.0, 1000.0)
    if model == "spring":
        p = dict(SPRING_DEFAULTS)
        for key, value in (params or {}).items():
            if key not in PARAM_RANGES:
                raise UnknownChoiceError("spring parameter", key, tuple(PARAM_RANGES))
            lo, hi = PARAM_RANGES[key]
            if not (lo <= float(value) <= hi):
                raise OutOfRangeError(key, value, lo, hi)
            p[key] = float(value)
        m = _spring(timeline, rate_hz, p)
    else:
        m = _interp(timeline, rate_hz, cosine=(model == "cosine"))
    return _track(timeline, rate_hz, model, m)
