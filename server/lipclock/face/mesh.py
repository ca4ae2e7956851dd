"""The mouth-node mesh as triangles, for renderers (served as ``GET /mesh``).

face/topology.py gives nodes and the spring edges; a renderer also needs surfaces. The
lips are bands between the outer and inner contours (corners shared), and the mouth
cavity is the band between the inner upper and inner lower edges. Each band is cut into
quads along matching contour indices, two triangles per quad, plus one triangle at each
corner, all counter-clockwise with y up. Rest positions are the ``rest`` viseme.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from .shape import NODES
from .topology import topology
from .visemes import viseme_nodes

_N_CONTOUR = 5  # interior points per lip contour (face/shape.py)


@dataclass(frozen=True)
class MouthMesh:
    nodes: tuple[str, ...]
    rest: np.ndarray  # (N, 2) mm, y up, origin at the mouth centre at rest
    edges: np.ndarray  # (E, 2) node indices
    triangles: np.ndarray  # (T, 3) node indices, counter-clockwise (y up)
    regions: dict[str, tuple[int, ...]]  # region name -> triangle indices


def band(top: list[str], bottom: list[str]) -> list[tuple[str, str, str]]:
    """Triangles between two contours that share their end points (the mouth corners).

    ``top`` lies above ``bottom``; both run left to right and have the same length.
    """
    if len(top) != len(bottom) or top[0] != bottom[0] or top[-1] != bottom[-1]:
        raise ValueError("band contours must have equal length and shared end points")
    tris = [(top[0], bottom[1], top[1])]
    for k in range(1, len(top) - 2):
        a, b, c, d = top[k], top[k + 1], bottom[k + 1], bottom[k]
        tris += [(a, d, c), (a, c, b)]
    tris.append((top[-2], bottom[-2], top[-1]))
    return tris


def _contour(prefix: str) -> list[str]:
    return ["corner_l", *(f"{prefix}_{i}" for i in range(_N_CONTOUR)), "corner_r"]


def build_mouth_mesh(rest: np.ndarray) -> MouthMesh:
    index = {n: i for i, n in enumerate(NODES)}
    parts = {
        "upper_lip": band(_contour("outer_upper"), _contour("inner_upper")),
        "lower_lip": band(_contour("inner_lower"), _contour("outer_lower")),
        "cavity": band(_contour("inner_upper"), _contour("inner_lower")),
    }
    triangles: list[tuple[int, int, int]] = []
    regions: dict[str, tuple[int, ...]] = {}
    for name, tris in parts.items():
        start = len(triangles)
        triangles += [(index[a], index[b], index[c]) for a, b, c in tris]
        regions[name] = tuple(range(start, len(triangles)))
    return MouthMesh(NODES, np.asarray(rest, dtype=np.float64), topology().edges,
                     np.array(triangles, dtype=np.int64), regions)


@cache
def mouth_mesh() -> MouthMesh:
    return build_mouth_mesh(viseme_nodes()["rest"])


def mesh_json(mesh: MouthMesh | None = None) -> dict[str, Any]:
    m = mesh or mouth_mesh()
    return {"nodes": list(m.nodes), "rest": [[float(x), float(y)] for x, y in m.rest],
            "edges": m.edges.tolist(), "triangles": m.triangles.tolist(),
            "regions": {k: list(v) for k, v in m.regions.items()},
            "units": "mm", "origin": "mouth centre, y up"}
