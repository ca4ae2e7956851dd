// Where the face's features sit (mm, y up, origin at the mouth centre at rest) and how the
// texture image maps onto them. The JSON between the markers is also read by
// scripts/make_face_texture.py, so the painted face and the mesh cannot drift apart:
// keep it strict JSON (no comments, double quotes) and edit the why-notes here instead.
//
//  head: outline from chin (bottom_mm) to crown (top_mm); widest (half_width_mm) at the
//        cheekbones (widest_y_mm); the jaw narrows with exponent jaw_exp (smaller = more V).
//  eyes: centre (mirrored), half width, lid heights above/below the centre, lid fold.
//        Adult eyes are ~30 mm wide, ~62 mm apart (pupils), ~65 mm above the mouth.
//  brows: inner, peak and outer points of the left brow (mirrored), thickness inner/outer.
//  nose: tip and nostrils; bulge heights give the shaded look its 3-D relief.
//  texture: the face box (mm) mapped onto the image above atlas_top (v from top); the lips
//        are painted separately in the strip below it (lips_box in mm), so the skin under
//        the mouth carries no lips and an opening mouth never smears painted lips.

// LAYOUT-JSON-BEGIN
export const LAYOUT = {
  "head": {"bottom_mm": -56, "top_mm": 156, "half_width_mm": 74, "widest_y_mm": 40,
           "jaw_exp": 2.6, "crown_exp": 2.4, "min_half_width_mm": 14},
  "eyes": {"centre_mm": [31, 64], "half_width_mm": 14, "upper_mm": 6.5, "lower_mm": 4.0,
           "fold_mm": 11.0, "iris_mm": 5.6, "pupil_mm": 2.4},
  "brows": {"inner_mm": [13, 82], "peak_mm": [32, 89], "outer_mm": [48, 83],
            "thick_inner_mm": 4.6, "thick_outer_mm": 1.8},
  "nose": {"tip_mm": [0, 30], "nostril_mm": [6.5, 25], "nostril_r_mm": [3.2, 1.7]},
  "hair": {"line_mm": 120, "drop_mm": 34, "side_x_mm": 62, "side_y_mm": 60},
  "texture": {"size_px": [512, 512], "face_box_mm": [-90, -66, 90, 162], "atlas_top_px": 448,
              "lips_box_mm": [-30, -14, 30, 12], "lips_px": [0, 448, 256, 512]}
};
// LAYOUT-JSON-END

// Texture coordinates (0..1, v down) of a rest position on the face, or on the lips atlas.
export function faceUV(x, y) {
  const t = LAYOUT.texture, [x0, y0, x1, y1] = t.face_box_mm, [w, h] = t.size_px;
  return [(x - x0) / (x1 - x0), ((y1 - y) / (y1 - y0)) * (t.atlas_top_px / h)];
}

export function lipsUV(x, y) {
  const t = LAYOUT.texture, [x0, y0, x1, y1] = t.lips_box_mm, [px0, py0, px1, py1] = t.lips_px;
  const [w, h] = t.size_px;
  return [(px0 + ((x - x0) / (x1 - x0)) * (px1 - px0)) / w,
          (py0 + ((y1 - y) / (y1 - y0)) * (py1 - py0)) / h];
}

// Half width of the head outline at height y (mm): a super-ellipse above the widest
// line, a narrower one (the jaw) below it.
export function headHalfWidth(y) {
  const h = LAYOUT.head;
  const up = y >= h.widest_y_mm;
  const span = up ? h.top_mm - h.widest_y_mm : h.widest_y_mm - h.bottom_mm;
  const e = up ? h.crown_exp : h.jaw_exp;
  const u = Math.min(1, Math.abs(y - h.widest_y_mm) / span);
  return Math.max(h.min_half_width_mm, h.half_width_mm * Math.pow(1 - Math.pow(u, e), 1 / e));
}

// Height of the face surface (mm toward the viewer) at a rest position: an ellipsoid
// head plus a nose, brow ridge, cheekbones and eye sockets. Only its slopes matter: they
// give per-vertex normals for the shaded look.
export function faceDepth(x, y) {
  const hw = headHalfWidth(y), n = LAYOUT.nose, e = LAYOUT.eyes;
  const g = (dx, dy, sx, sy) => Math.exp(-0.5 * ((dx / sx) ** 2 + (dy / sy) ** 2));
  const r = Math.min(1, Math.abs(x) / (hw + 6));
  let z = 60 * Math.sqrt(1 - r * r);
  z += 12 * g(x - n.tip_mm[0], y - (n.tip_mm[1] + 8), 7.5, 15);   // the nose ridge and tip
  z += 4 * g(Math.abs(x) - 30, y - 84, 16, 5);                     // brow ridge
  z += 5 * g(Math.abs(x) - 40, y - 40, 12, 12);                    // cheekbones
  z -= 6 * g(Math.abs(x) - e.centre_mm[0], y - e.centre_mm[1], 13, 8);  // eye sockets
  z += 5 * g(x, y, 22, 10);                                        // the lips bulge forward
  z += 4 * g(x, y + 40, 16, 10);                                   // the chin
  return z;
}
