"""face/mesh.py: the lips and cavity tile the mouth, counter-clockwise, for every viseme."""

from __future__ import annotations

import numpy as np
import pytest

from lipclock.face.mesh import band, build_mouth_mesh, mesh_json, mouth_mesh
from lipclock.face.shape import NODES
from lipclock.face.visemes import viseme_nodes


def signed_areas(pts: np.ndarray, tris: np.ndarray) -> np.ndarray:
    a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    ab, ac = b - a, c - a
    return 0.5 * (ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0])


def polygon_area(pts: np.ndarray, names: list[str]) -> float:
    p = pts[[NODES.index(n) for n in names]]
    return 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))


def ring(top: str, bottom: str) -> list[str]:
    """A closed counter-clockwise outline: left to right along bottom, back along top."""
    mid = [f"{bottom}_{i}" for i in range(5)]
    return ["corner_l", *mid, "corner_r", *[f"{top}_{i}" for i in reversed(range(5))]]


def test_every_node_is_known_and_regions_partition_the_triangles():
    m = mouth_mesh()
    assert m.nodes == NODES and m.rest.shape == (len(NODES), 2)
    assert m.triangles.min() >= 0 and m.triangles.max() < len(NODES)
    every = sorted(i for r in m.regions.values() for i in r)
    assert every == list(range(len(m.triangles)))
    assert set(m.regions) == {"upper_lip", "lower_lip", "cavity"}


@pytest.mark.parametrize("viseme", ["open", "rounded", "alveolar", "postalveolar"])
def test_triangles_are_counter_clockwise_and_tile_each_region(viseme):
    pts = viseme_nodes()[viseme]
    m = build_mouth_mesh(pts)
    areas = signed_areas(pts, m.triangles)
    assert (areas > 0).all()  # an open mouth: no flipped or degenerate triangle
    tri = {k: areas[list(v)].sum() for k, v in m.regions.items()}
    assert tri["upper_lip"] == pytest.approx(polygon_area(pts, ring("outer_upper", "inner_upper")))
    assert tri["lower_lip"] == pytest.approx(polygon_area(pts, ring("inner_lower", "outer_lower")))
    assert tri["cavity"] == pytest.approx(polygon_area(pts, ring("inner_upper", "inner_lower")))


def test_closed_lips_leave_a_cavity_of_zero_area():
    pts = viseme_nodes()["closed"]
    m = build_mouth_mesh(pts)
    cavity = signed_areas(pts, m.triangles[list(m.regions["cavity"])])
    assert np.allclose(cavity, 0, atol=1e-6)


def test_band_rejects_contours_that_do_not_share_corners():
    with pytest.raises(ValueError):
        band(["a", "b", "c"], ["x", "y", "c"])


def test_json_shape():
    j = mesh_json()
    assert j["units"] == "mm" and j["origin"] == "mouth centre, y up"
    assert len(j["rest"]) == len(j["nodes"]) == len(NODES)
    assert all(len(t) == 3 for t in j["triangles"]) and all(len(e) == 2 for e in j["edges"])
