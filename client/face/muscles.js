// Expressions as DECface linear muscles (Waters 1987; Waters & Levergood 1993).
//
// A linear muscle runs from its attachment (on bone: it does not move) to its insertion
// (in the skin). Contracting it pulls skin points toward the attachment, by an amount
// that falls off with the angle between the point and the muscle's axis (zero at the
// zone's edge, `zone_deg`) and with the point's distance D from the attachment: rising
// from the attachment to `rs_mm` (the belly, where pull is strongest), then easing to
// zero at `rf_mm` (past the insertion). `k_mm` is the pull at full contraction where both
// falloffs are 1. Every row is mirrored: x below is the left side (negative x).
//
// Expressions drive muscles with weights; each setExpression key is 0..1.

export const MUSCLES = [
  // smile: zygomatic major, from the cheekbone to the mouth corner. Its pull, up and out
  // toward the cheekbone, is what lifts and widens the corners in a smile. rs just short
  // of the corner (46 mm from the attachment) so the corner and cheek move most.
  { name: "zygomatic_major", expr: { smile: 1 }, attach: [-60, 36], insert: [-25, 0],
    zone_deg: 38, rs_mm: 38, rf_mm: 66, k_mm: 11 },
  // brow raise: frontalis, from high on the forehead (it really ends in the scalp's
  // aponeurosis, which does not move much) down into the brow skin. rs at the brow so
  // the brows rise most and the forehead above them bunches less.
  { name: "frontalis", expr: { brow: 1 }, attach: [-31, 128], insert: [-31, 86],
    zone_deg: 34, rs_mm: 42, rf_mm: 60, k_mm: 8 },
  // frown: corrugator supercilii, from the bone at the root of the nose into the middle
  // of the brow: it pulls the brows down and in (the vertical frown lines).
  { name: "corrugator", expr: { frown: 1 }, attach: [-7, 74], insert: [-28, 88],
    zone_deg: 45, rs_mm: 20, rf_mm: 44, k_mm: 7 },
  // frown: depressor anguli oris, from the jaw's lower edge up into the mouth corner:
  // pulls the corners down (and a little out), the sad/disapproving mouth.
  { name: "depressor_anguli_oris", expr: { frown: 1 }, attach: [-36, -36], insert: [-25, 0],
    zone_deg: 35, rs_mm: 26, rf_mm: 48, k_mm: 8 },
];

export const EXPRESSIONS = ["smile", "brow", "frown"];

// Displacement (mm per unit contraction) of a rest point under one muscle, or null.
function pull(m, x, y) {
  const [ax, ay] = m.attach, [ix, iy] = m.insert;
  const px = x - ax, py = y - ay, D = Math.hypot(px, py);
  if (D < 1e-6 || D > m.rf_mm) return null;
  const mx = ix - ax, my = iy - ay, L = Math.hypot(mx, my);
  const cos = (px * mx + py * my) / (D * L);
  const angle = Math.acos(Math.max(-1, Math.min(1, cos)));
  const zone = (m.zone_deg * Math.PI) / 180;
  if (angle >= zone) return null;
  const A = Math.cos((angle / zone) * (Math.PI / 2));
  const R = D < m.rs_mm ? Math.cos((1 - D / m.rs_mm) * (Math.PI / 2))
                        : Math.cos(((D - m.rs_mm) / (m.rf_mm - m.rs_mm)) * (Math.PI / 2));
  const s = (A * R * m.k_mm) / D;
  return [-px * s, -py * s];
}

// Each muscle, mirrored, as sparse per-vertex displacement tables over `rest` (a flat
// Float32Array x,y,...), for the vertex indices in `movable`. Contraction is linear in
// the tables, so a frame costs one multiply-add per affected vertex.
export function buildMuscles(rest, movable) {
  const out = [];
  for (const m of MUSCLES) {
    for (const side of [1, -1]) {
      const mm = { ...m, attach: [m.attach[0] * side, m.attach[1]],
                   insert: [m.insert[0] * side, m.insert[1]] };
      const idx = [], d = [];
      for (const v of movable) {
        const p = pull(mm, rest[2 * v], rest[2 * v + 1]);
        if (p) { idx.push(v); d.push(p[0], p[1]); }
      }
      out.push({ name: `${m.name}_${side > 0 ? "r" : "l"}`, expr: m.expr,
                 idx: Uint16Array.from(idx), d: Float32Array.from(d) });
    }
  }
  return out;
}

// pos += contraction * table, for every muscle the expression drives.
export function applyMuscles(muscles, expr, pos) {
  for (const m of muscles) {
    let c = 0;
    for (const k in m.expr) c += (expr[k] || 0) * m.expr[k];
    if (c <= 0) continue;
    const idx = m.idx, d = m.d;
    for (let i = 0; i < idx.length; i++) {
      pos[2 * idx[i]] += c * d[2 * i];
      pos[2 * idx[i] + 1] += c * d[2 * i + 1];
    }
  }
}
