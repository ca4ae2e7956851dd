"""``lipclock plot`` writes a non-empty image through the CLI."""

from __future__ import annotations

import pytest

from lipclock.cli import main

pytest.importorskip("matplotlib")


def test_plot_writes_png(tmp_path) -> None:
    out = tmp_path / "fig.png"
    assert main(["plot", "Mom made a map.", "-o", str(out)]) == 0
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000


def test_plot_bad_input_is_a_typed_error(tmp_path, capsys) -> None:
    assert main(["plot", "   ", "-o", str(tmp_path / "x.png")]) == 2
    assert "error" in capsys.readouterr().err
