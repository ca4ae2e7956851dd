"""scripts/make_face_texture.py: the shipped client/assets/face.png is exactly what the
script paints (so it can be regenerated and reviewed), and the layout JSON it reads from
client/face/layout.js parses."""

from __future__ import annotations

import importlib.util
import struct
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def load_script():
    spec = importlib.util.spec_from_file_location("make_face_texture",
                                                  ROOT / "scripts" / "make_face_texture.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_regenerating_the_texture_gives_the_committed_bytes(tmp_path):
    mod = load_script()
    out = tmp_path / "face.png"
    mod.main(["--out", str(out)])
    assert out.read_bytes() == (ROOT / "client" / "assets" / "face.png").read_bytes()


def test_texture_is_a_png_of_the_layout_size():
    mod = load_script()
    layout = mod.load_layout()
    data = (ROOT / "client" / "assets" / "face.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    w, h = struct.unpack(">II", data[16:24])
    assert [w, h] == layout["texture"]["size_px"]
    assert layout["texture"]["atlas_top_px"] < h
