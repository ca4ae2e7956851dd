"""The mouth mesh as data: nodes (with roles) and edges, from ``viseme_tables/topology.tsv``.

Node names must be the ones face/shape.py knows how to place, each exactly once;
edges must join known nodes. Errors name ``file:line``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from ..errors import TableError
from ..tables import iter_tsv, package_file
from .shape import NODES

ROLES = frozenset({"corner", "outer_lip", "inner_lip", "upper_teeth", "lower_teeth", "jaw"})


@dataclass(frozen=True)
class Topology:
    nodes: tuple[str, ...]
    roles: dict[str, str]
    edges: np.ndarray  # (E, 2) node indices


def load_topology(path: Path) -> Topology:
    names: list[str] = []
    roles: dict[str, str] = {}
    edges: list[tuple[int, int]] = []
    pending: list[tuple[int, str, str]] = []
    for line, f in iter_tsv(path):
        if f[0] == "node":
            if len(f) != 3:
                raise TableError(path, line, "node rows are: node NAME ROLE")
            _, name, role = f
            if name not in NODES:
                raise TableError(path, line, f"unknown node {name!r} (face/shape.py places "
                                             "only its own nodes)")
            if name in roles:
                raise TableError(path, line, f"duplicate node {name!r}")
            if role not in ROLES:
                raise TableError(path, line, f"unknown role {role!r}; allowed: "
                                             f"{', '.join(sorted(ROLES))}")
            names.append(name)
            roles[name] = role
        elif f[0] == "edge":
            if len(f) != 3:
                raise TableError(path, line, "edge rows are: edge A B")
            pending.append((line, f[1], f[2]))
        else:
            raise TableError(path, line, f"row kind must be node or edge, got {f[0]!r}")
    missing = [n for n in NODES if n not in roles]
    if missing:
        raise TableError(path, 1, f"missing nodes: {', '.join(missing)}")
    if tuple(names) != NODES:
        raise TableError(path, 1, "nodes must be listed in the mesh order of face/shape.py")
    for line, a, b in pending:
        for n in (a, b):
            if n not in roles:
                raise TableError(path, line, f"edge to unknown node {n!r}")
        if a == b:
            raise TableError(path, line, f"edge from {a!r} to itself")
        edges.append((NODES.index(a), NODES.index(b)))
    return Topology(tuple(names), roles, np.array(edges, dtype=np.int64))


@cache
def topology() -> Topology:
    return load_topology(package_file("lipclock.viseme_tables", "topology.tsv"))
