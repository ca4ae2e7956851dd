"""viseme_tables: topology and per-viseme node positions load, and fail with file:line."""

from __future__ import annotations

import pytest

from lipclock.errors import TableError
from lipclock.face.shape import NODES
from lipclock.face.topology import load_topology, topology
from lipclock.face.visemes import load_viseme_nodes, shapes, viseme_nodes
from lipclock.tables import package_file


def test_shipped_tables_load():
    topo = topology()
    assert topo.nodes == NODES and len(NODES) >= 24
    assert {"corner", "outer_lip", "inner_lip", "upper_teeth", "lower_teeth", "jaw"} <= set(
        topo.roles.values())
    assert len(topo.edges) > len(NODES)
    table = viseme_nodes()
    assert set(table) == set(shapes())
    assert all(v.shape == (len(NODES), 2) for v in table.values())
    i_up, i_lo = NODES.index("inner_upper_2"), NODES.index("inner_lower_2")
    assert table["open"][i_up, 1] - table["open"][i_lo, 1] > 10  # open really is open
    assert table["closed"][i_up, 1] - table["closed"][i_lo, 1] == pytest.approx(0, abs=1e-6)


def test_topology_errors(tmp_path):
    src = package_file("lipclock.viseme_tables", "topology.tsv").read_text()
    bad = tmp_path / "t.tsv"
    bad.write_text(src.replace("edge\tteeth_lower_c\tchin", "edge\tteeth_lower_c\tnose"))
    with pytest.raises(TableError, match="unknown node 'nose'"):
        load_topology(bad)
    bad.write_text(src.replace("node\tchin\tjaw", "node\tchin\tbeard"))
    with pytest.raises(TableError, match=r"t\.tsv:\d+: unknown role"):
        load_topology(bad)
    bad.write_text("\n".join(line for line in src.splitlines() if "\tchin\tjaw" not in line))
    with pytest.raises(TableError, match="missing nodes: chin"):
        load_topology(bad)


def test_viseme_node_errors(tmp_path):
    src = package_file("lipclock.viseme_tables", "viseme_nodes.tsv").read_text().splitlines()
    bad = tmp_path / "n.tsv"
    rows = [r for r in src if not r.startswith("open\tchin")]
    bad.write_text("\n".join(rows))
    with pytest.raises(TableError, match="open: missing nodes chin"):
        load_viseme_nodes(bad, shapes())
    rows = [r.replace("open\tchin\t0", "open\tchin\tnan") if r.startswith("open\tchin")
            else r for r in src]
    bad.write_text("\n".join(rows))
    with pytest.raises(TableError, match=r"n\.tsv:\d+: x_mm.*finite"):
        load_viseme_nodes(bad, shapes())
    bad.write_text("grin\tchin\t0\t-30\n")
    with pytest.raises(TableError, match=r"n\.tsv:1: unknown viseme"):
        load_viseme_nodes(bad, shapes())
