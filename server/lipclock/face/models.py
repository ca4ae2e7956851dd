"""Mouth motion models: viseme targets -> node trajectories on the audio clock.

* ``linear`` / ``cosine``: interpolation between viseme targets placed at phone
  centres (the DECface baselines; Waters & Levergood 1993).
* ``spring``: Waters-style damped springs on every mesh node (face/spring.py),
  integrated on a fixed step of whole audio samples; parameters per node group
  in ``viseme_tables/dynamics.toml``, overridable per call with keys such as
  ``"lips.stiffness"`` or ``"integration.step_s"``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import _kernels
from ..errors import OutOfRangeError, UnknownChoiceError
from ..speech.timeline import Timeline
from ..tables import package_file
from .shape import LOWER_LIP_MID, NODES, UPPER_LIP_MID, nodes_from_measures
from .spring import default_dynamics, load_dynamics, spring_nodes
from .track import MouthTrack
from .visemes import viseme_nodes, viseme_of

MOUTH_MODELS = ("linear", "cosine", "spring", "bigram")

CHIN = NODES.index("chin")
CHIN_ZERO_Y = -32.0  # chin y with the jaw at 0 mm (face/shape.py)


def measures_from_nodes(nodes: np.ndarray) -> dict[str, np.ndarray]:
    """Named measures per frame (mm): lip_gap at the midline, width corner to corner, jaw drop."""
    gap = nodes[:, UPPER_LIP_MID, 1] - nodes[:, LOWER_LIP_MID, 1]
    width = nodes[:, 1, 0] - nodes[:, 0, 0]
    jaw = CHIN_ZERO_Y - nodes[:, CHIN, 1]
    return {"lip_gap": np.maximum(gap, 0.0).astype(np.float32),
            "width": width.astype(np.float32), "jaw": jaw.astype(np.float32)}


MAX_NODE_SPEED_MM_S = 500.0  # lips at face scale: 0.5 m/s (docs/mouth.md)


def limit_node_speed(nodes: np.ndarray, max_step_mm: float) -> np.ndarray:
    """No node moves more than ``max_step_mm`` between frames: it follows late instead.

    ``nodes`` is (n_frames, N, 2) mm; returns a new float64 array. The loop is C."""
    out = np.array(nodes, dtype=np.float64)  # a fresh C-contiguous copy, limited in place
    _limit_in_place(out, max_step_mm)
    return out


def _limit_in_place(nodes: np.ndarray, max_step_mm: float) -> None:
    """:func:`limit_node_speed` on a C-contiguous float64 array, modified in place."""
    if nodes.ndim != 3 or nodes.shape[2] != 2:
        raise ValueError(f"nodes must be (n_frames, N, 2), got {nodes.shape}")
    if nodes.size:
        _kernels.limit_node_speed(nodes, nodes.shape[1], float(max_step_mm))


def _track(timeline: Timeline, rate_hz: float, model: str, nodes: np.ndarray) -> MouthTrack:
    # the documented physiological limit holds for every model (spring and bigram already
    # stay under it; the interpolation baselines can exceed it in fast speech). ``nodes``
    # is the model's own new array: limited in place (converted first if not float64).
    nodes = np.ascontiguousarray(nodes, dtype=np.float64)
    _limit_in_place(nodes, MAX_NODE_SPEED_MM_S / rate_hz)
    nodes = nodes.astype(np.float32)
    return MouthTrack(timeline.sample_rate, rate_hz, model, NODES, nodes,
                      measures_from_nodes(nodes))


def _frame_samples(timeline: Timeline, rate_hz: float) -> np.ndarray:
    n = int(math.floor(timeline.num_samples * rate_hz / timeline.sample_rate)) + 1
    return np.round(np.arange(n) * (timeline.sample_rate / rate_hz))


def _node_targets(timeline: Timeline) -> tuple[np.ndarray, np.ndarray]:
    """Per phone: centre sample and its viseme's node positions (viseme_nodes.tsv)."""
    table = viseme_nodes()
    rest = table["rest"]
    centres = np.array([(p.start + p.end) // 2 for p in timeline.phones], dtype=np.float64)
    nodes = np.stack([table[viseme_of(p.phone)] for p in timeline.phones])
    schwa = np.array([p.phone == "AH0" for p in timeline.phones])
    nodes[schwa] = rest + 0.6 * (nodes[schwa] - rest)  # schwa: a smaller opening
    return centres, nodes


def _interp(timeline: Timeline, rate_hz: float, cosine: bool) -> np.ndarray:
    """Node positions interpolated between viseme targets at phone centres (DECface)."""
    centres, vecs = _node_targets(timeline)
    fs = _frame_samples(timeline, rate_hz)
    idx = np.clip(np.searchsorted(centres, fs, side="right") - 1, 0, len(centres) - 1)
    nxt = np.minimum(idx + 1, len(centres) - 1)
    span = np.maximum(centres[nxt] - centres[idx], 1.0)
    u = np.clip((fs - centres[idx]) / span, 0.0, 1.0)
    if cosine:
        u = 0.5 - 0.5 * np.cos(np.pi * u)
    return vecs[idx] + (vecs[nxt] - vecs[idx]) * u[:, None, None]


def mouth_for(timeline: Timeline, model: str = "spring", rate_hz: float = 100.0,
              params: dict[str, Any] | None = None) -> MouthTrack:
    if model not in MOUTH_MODELS:
        raise UnknownChoiceError("mouth_model", model, MOUTH_MODELS)
    if not (1.0 <= rate_hz <= 1000.0):
        raise OutOfRangeError("rate_hz", rate_hz, 1.0, 1000.0)
    if model == "spring":
        d = default_dynamics() if not params else load_dynamics(
            package_file("lipclock.viseme_tables", "dynamics.toml"), params)
        nodes = spring_nodes(timeline, rate_hz, d)
    elif model == "bigram":
        from .bigram import bigram_measures

        nodes = nodes_from_measures(bigram_measures(
            timeline, _frame_samples(timeline, rate_hz), params))
    else:
        nodes = _interp(timeline, rate_hz, cosine=(model == "cosine"))
    return _track(timeline, rate_hz, model, nodes)
