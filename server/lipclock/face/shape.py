"""Mouth-node mesh built from four articulatory measures (mm, frontal view, y up).

Nodes: outer and inner lip contours, upper and lower teeth edges, jaw/chin
points and mouth corners (29 named nodes). The lower teeth and chin follow
the jaw; the lips follow lip gap, width and protrusion. Origin: mouth centre
at rest.
"""

from __future__ import annotations

import numpy as np

_XS = np.array([-1.0, -0.7, -0.35, 0.0, 0.35, 0.7, 1.0])  # fractions of half-width

NODES: tuple[str, ...] = (
    ("corner_l", "corner_r")
    + tuple(f"outer_upper_{i}" for i in range(5))
    + tuple(f"outer_lower_{i}" for i in range(5))
    + tuple(f"inner_upper_{i}" for i in range(5))
    + tuple(f"inner_lower_{i}" for i in range(5))
    + ("teeth_upper_l", "teeth_upper_c", "teeth_upper_r",
       "teeth_lower_l", "teeth_lower_c", "teeth_lower_r", "chin")
)
N_NODES = len(NODES)
UPPER_LIP_MID = NODES.index("inner_upper_2")
LOWER_LIP_MID = NODES.index("inner_lower_2")


def nodes_from_measures(m: np.ndarray) -> np.ndarray:
    """``m``: (n, 4) lip_gap, width, protrusion, jaw (mm) -> (n, N_NODES, 2) float32."""
    gap, width, prot, jaw = (m[:, i][:, None] for i in range(4))
    half = width / 2.0
    xs = _XS[1:-1][None, :] * half  # 5 interior x positions
    bulge = np.sqrt(np.clip(1.0 - (_XS[1:-1][None, :]) ** 2, 0.0, 1.0))
    up_in = 0.35 * gap * bulge
    lo_in = -0.65 * gap * bulge
    thick_u = 7.0 + 0.4 * prot
    thick_l = 9.0 + 0.5 * prot
    out_u = up_in + thick_u * (0.4 + 0.6 * bulge)
    out_l = lo_in - thick_l * (0.4 + 0.6 * bulge)
    n = m.shape[0]
    nodes = np.empty((n, N_NODES, 2), dtype=np.float32)
    corner_y = -0.1 * jaw[:, 0]
    nodes[:, 0] = np.stack([-half[:, 0], corner_y], axis=1)
    nodes[:, 1] = np.stack([half[:, 0], corner_y], axis=1)
    for block, ys in enumerate((out_u, out_l, up_in, lo_in)):
        base = 2 + 5 * block
        nodes[:, base:base + 5, 0] = xs
        nodes[:, base:base + 5, 1] = ys
    tx = np.array([-12.0, 0.0, 12.0])
    nodes[:, 22:25, 0] = tx
    nodes[:, 22:25, 1] = 1.5
    nodes[:, 25:28, 0] = tx
    nodes[:, 25:28, 1] = -1.5 - 0.9 * jaw
    nodes[:, 28, 0] = 0.0
    nodes[:, 28, 1] = -32.0 - jaw[:, 0]
    return nodes
