"""Paint the textured look's face image: client/assets/face.png (deterministic).

The image is laid out as client/face/layout.js says (its LAYOUT JSON is read from
there, so the painting and the mesh share one set of feature positions): the face box
in mm fills the image above ``atlas_top_px``; the lips, at rest, are painted in a strip
below it, so the skin under the mouth has no lips on it.

Everything is numpy arithmetic on pixel grids (no randomness, no fonts, no image
library): a lit skin surface from the same depth field the shaded look uses, cheeks,
eye shadow, brows, nose shading and nostrils, hair with strands, and lips with a
highlight. The PNG is written with zlib + struct. Usage:

    python scripts/make_face_texture.py [--out client/assets/face.png]
"""

from __future__ import annotations

import argparse
import json
import re
import struct
import zlib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
LAYOUT_JS = ROOT / "client" / "face" / "layout.js"
OUT = ROOT / "client" / "assets" / "face.png"

SKIN = np.array([0.94, 0.76, 0.63])
HAIR = np.array([0.25, 0.16, 0.11])


def load_layout(path: Path = LAYOUT_JS) -> dict:
    text = path.read_text(encoding="utf-8")
    m = re.search(r"LAYOUT-JSON-BEGIN\s*export const LAYOUT = (\{.*?\});\s*// LAYOUT-JSON-END",
                  text, re.S)
    if not m:
        raise SystemExit(f"{path}: no LAYOUT JSON between the markers")
    return json.loads(m.group(1))


def smooth(a: float, b: float, x: np.ndarray) -> np.ndarray:
    t = np.clip((x - a) / (b - a), 0.0, 1.0)
    return t * t * (3 - 2 * t)


def gauss(dx, dy, sx, sy):
    return np.exp(-0.5 * ((dx / sx) ** 2 + (dy / sy) ** 2))


def head_half_width(L: dict, y: np.ndarray) -> np.ndarray:
    h = L["head"]
    up = y >= h["widest_y_mm"]
    span = np.where(up, h["top_mm"] - h["widest_y_mm"], h["widest_y_mm"] - h["bottom_mm"])
    e = np.where(up, h["crown_exp"], h["jaw_exp"])
    u = np.minimum(1.0, np.abs(y - h["widest_y_mm"]) / span)
    w = h["half_width_mm"] * (1 - u ** e) ** (1 / e)
    return np.maximum(h["min_half_width_mm"], w)


def face_depth(L: dict, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The same relief as faceDepth() in client/face/layout.js."""
    n, eye = L["nose"], L["eyes"]
    r = np.minimum(1.0, np.abs(x) / (head_half_width(L, y) + 6))
    z = 60 * np.sqrt(1 - r * r)
    z += 12 * gauss(x - n["tip_mm"][0], y - (n["tip_mm"][1] + 8), 7.5, 15)
    z += 4 * gauss(np.abs(x) - 30, y - 84, 16, 5)
    z += 5 * gauss(np.abs(x) - 40, y - 40, 12, 12)
    z -= 6 * gauss(np.abs(x) - eye["centre_mm"][0], y - eye["centre_mm"][1], 13, 8)
    z += 5 * gauss(x, y, 22, 10)
    z += 4 * gauss(x, y + 40, 16, 10)
    return z


def over(img: np.ndarray, colour, alpha: np.ndarray) -> None:
    """Composite a colour onto img (H, W, 3) with per-pixel alpha (H, W), in place."""
    a = np.clip(alpha, 0.0, 1.0)[..., None]
    img *= 1 - a
    img += a * np.asarray(colour, dtype=np.float64)


def brow_distance(L: dict, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance (mm) to the nearer brow's centre line and the position t (0 inner..1 outer)."""
    b = L["brows"]
    t = np.linspace(0.0, 1.0, 64)
    ctrl = [2 * b["peak_mm"][k] - (b["inner_mm"][k] + b["outer_mm"][k]) / 2 for k in (0, 1)]
    px = (1 - t) ** 2 * b["inner_mm"][0] + 2 * t * (1 - t) * ctrl[0] + t ** 2 * b["outer_mm"][0]
    py = (1 - t) ** 2 * b["inner_mm"][1] + 2 * t * (1 - t) * ctrl[1] + t ** 2 * b["outer_mm"][1]
    ax = np.abs(x)[..., None]
    d2 = (ax - px) ** 2 + (y[..., None] - py) ** 2
    k = np.argmin(d2, axis=-1)
    return np.sqrt(np.take_along_axis(d2, k[..., None], -1)[..., 0]), t[k]


def paint_face(L: dict, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    e, n, hair = L["eyes"], L["nose"], L["hair"]
    # lit skin: the depth field's normals, light from the upper left, soft
    step = 0.5
    dzx = (face_depth(L, x + step, y) - face_depth(L, x - step, y)) / (2 * step)
    dzy = (face_depth(L, x, y + step) - face_depth(L, x, y - step)) / (2 * step)
    norm = np.sqrt(dzx ** 2 + dzy ** 2 + 1)
    light = np.array([-0.35, 0.5, 0.8]) / np.linalg.norm([-0.35, 0.5, 0.8])
    lam = np.clip((-dzx * light[0] - dzy * light[1] + light[2]) / norm, 0, 1)
    shade = 0.62 + 0.45 * lam
    img = SKIN[None, None, :] * shade[..., None]
    img = np.clip(img, 0, 1)
    ax = np.abs(x)
    over(img, [0.92, 0.52, 0.5], 0.45 * gauss(ax - 40, y - 22, 13, 9))          # cheeks
    over(img, [0.95, 0.6, 0.55], 0.25 * gauss(x, y - 28, 5, 4))                  # nose tip
    over(img, [0.72, 0.5, 0.52], 0.45 * gauss(ax - e["centre_mm"][0], y - e["centre_mm"][1] - 7,
                                              13, 4.5))                        # eye shadow
    over(img, [0.6, 0.42, 0.38], 0.35 * gauss(ax - e["centre_mm"][0], y - e["centre_mm"][1] - 11,
                                              11, 1.2))                        # lid crease
    over(img, [0.62, 0.42, 0.36], 0.35 * gauss(ax - 8, y - 45, 2.2, 16))        # nose sides
    for s in (-1, 1):                                                            # nostrils
        over(img, [0.35, 0.17, 0.14], 0.9 * smooth(1.1, 0.8, np.hypot(
            (x - s * n["nostril_mm"][0]) / n["nostril_r_mm"][0],
            (y - n["nostril_mm"][1]) / n["nostril_r_mm"][1])))
    over(img, [0.7, 0.48, 0.42], 0.3 * gauss(ax - 10, y - 27, 3, 3))            # nose wings
    over(img, [0.75, 0.55, 0.48], 0.25 * gauss(x, y - 14, 3.5, 5))              # philtrum
    over(img, [0.7, 0.5, 0.45], 0.3 * gauss(x, y + 18, 14, 3))                  # under the lip
    over(img, [0.8, 0.6, 0.52], 0.25 * gauss(ax - 30, y + 3, 4, 5))             # smile folds
    # brows: tapered strokes with hair direction
    d, t = brow_distance(L, x, y)
    b = L["brows"]
    half = (b["thick_inner_mm"] + (b["thick_outer_mm"] - b["thick_inner_mm"]) * t) / 2
    strands = 0.92 + 0.08 * np.sin(ax * 3.1 + y * 1.3)
    over(img, [0.3, 0.2, 0.14], 0.95 * smooth(half + 0.6, half - 0.4, d) * strands)
    # hair, with strands that sweep from the parting
    line = hair["line_mm"] - hair["drop_mm"] * (x / hair["side_x_mm"]) ** 2
    mask = np.maximum(smooth(line - 3, line + 4, y),
                      smooth(hair["side_x_mm"] - 4, hair["side_x_mm"] + 3, ax)
                      * smooth(hair["side_y_mm"], hair["side_y_mm"] + 10, y))
    # strands: fine, low-contrast waves sweeping out from the parting, plus a sheen band
    sweep = x * 2.3 + 0.012 * (y - 170) ** 2 * np.sign(x + 1e-9)
    wave = 0.5 + 0.25 * np.sin(sweep) + 0.25 * np.sin(1.7 * sweep + 1.3)
    sheen = 0.35 * gauss(np.hypot(x, y - 60) - 88, 0, 7, 1) * smooth(-70, -10, -np.abs(x))
    hair_col = HAIR[None, None, :] * (0.85 + 0.25 * wave + sheen)[..., None]
    a = np.clip(mask, 0, 1)[..., None]
    return np.clip(img * (1 - a) + hair_col * a, 0, 1)


def paint_lips(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Lips at rest (face/shape.py: upper above y = 0, lower below), lit from above."""
    upper = np.array([0.7, 0.31, 0.35])
    lower = np.array([0.8, 0.4, 0.42])
    img = np.where((y >= 0)[..., None], upper, lower) * np.ones(x.shape + (1,))
    ax = np.abs(x)
    over(img, [0.4, 0.12, 0.15], 0.7 * smooth(2.2, 0.0, np.abs(y)))              # the meeting line
    over(img, [0.45, 0.15, 0.18], 0.6 * smooth(16, 25, ax))                     # corners
    over(img, [0.97, 0.72, 0.72], 0.45 * gauss(x, y + 4.5, 8, 1.6))             # lower highlight
    over(img, [0.9, 0.6, 0.6], 0.2 * gauss(ax - 6, y - 4, 4, 1.5))              # upper highlights
    img *= (0.975 + 0.025 * np.sin(x * 2.4))[..., None]                         # fine creases
    return np.clip(img, 0, 1)


def render(L: dict) -> np.ndarray:
    T = L["texture"]
    w, h = T["size_px"]
    top = T["atlas_top_px"]
    img = np.empty((h, w, 3))
    x0, y0, x1, y1 = T["face_box_mm"]
    px = (np.arange(w) + 0.5) / w
    py = (np.arange(top) + 0.5) / top
    X, Y = np.meshgrid(x0 + px * (x1 - x0), y1 - py * (y1 - y0))
    img[:top] = paint_face(L, X, Y)
    img[top:] = SKIN
    lx0, ly0, lx1, ly1 = T["lips_box_mm"]
    ax0, ay0, ax1, ay1 = T["lips_px"]
    qx = (np.arange(ax1 - ax0) + 0.5) / (ax1 - ax0)
    qy = (np.arange(ay1 - ay0) + 0.5) / (ay1 - ay0)
    LX, LY = np.meshgrid(lx0 + qx * (lx1 - lx0), ly1 - qy * (ly1 - ly0))
    img[ay0:ay1, ax0:ax1] = paint_lips(LX, LY)
    return np.round(img * 255).astype(np.uint8)


def png_bytes(rgb: np.ndarray) -> bytes:
    """An 8-bit RGB PNG: filter byte 0 on every row, one IDAT, fixed zlib level."""
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[r].tobytes() for r in range(h))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=OUT)
    args = ap.parse_args(argv)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_bytes(png_bytes(render(load_layout())))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
