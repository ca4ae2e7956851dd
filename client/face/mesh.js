// The face mesh (DECface style: a 2-D mesh whose mouth is the server's node mesh) and the
// rig that deforms it every frame. Everything is mm, y up, origin at the mouth centre.
//
// One flat vertex array holds every part, so a renderer uploads positions once a frame:
//   skin grid   rows x cols over the head outline; near the mouth its vertices follow the
//               lip nodes (inverse-distance weights with falloff), below the mouth they
//               follow the jaw (the chin node's drop), so cheeks and chin deform with speech
//   mouth nodes the streamed nodes (GET /mesh order), triangulated by the server
//   cavity      a copy of the mouth nodes coloured as the mouth's inside
//   teeth       upper and lower incisor rows, hung from the teeth nodes
//   eyes        lid fold, lid edge (moves down to blink), lower lid, lashes, iris, pupil
//   brows, nostrils, body (neck and shoulders; never moves)
// Layers are index ranges into one index array; each is one draw call.

import { LAYOUT, faceUV, lipsUV, headHalfWidth, faceDepth } from "./layout.js";
import { buildMuscles, applyMuscles } from "./muscles.js";

const COLS = 37, ROWS = 55;
const DRIVERS = ["corner_l", "corner_r", ...[0, 1, 2, 3, 4].flatMap((i) => [`outer_upper_${i}`, `outer_lower_${i}`])];
const SKIN = [0.93, 0.75, 0.62], LIP = [0.76, 0.36, 0.38], HAIR = [0.25, 0.16, 0.11];
const smooth = (a, b, x) => { const t = Math.min(1, Math.max(0, (x - a) / (b - a))); return t * t * (3 - 2 * t); };
const mix = (a, b, t) => a.map((v, i) => v + (b[i] - v) * t);
const gauss = (dx, dy, sx, sy) => Math.exp(-0.5 * ((dx / sx) ** 2 + (dy / sy) ** 2));

// How much a rest point follows the jaw: nothing above the mouth corners, fully on the
// chin; less toward the jaw's angles, which sit closer to the hinge and so drop less.
export function jawWeight(x, y) {
  const r = x / headHalfWidth(y);
  return smooth(4, -24, y) * Math.max(0, 1 - 0.4 * r * r);
}

// Base colour of the skin at a rest point in the shaded look: hair, blush, eye shadow.
function skinColour(x, y) {
  const h = LAYOUT.hair, e = LAYOUT.eyes;
  let c = SKIN;
  c = mix(c, [0.9, 0.55, 0.5], 0.55 * gauss(Math.abs(x) - 40, y - 22, 12, 9));   // cheeks
  c = mix(c, [0.78, 0.58, 0.5], 0.5 * gauss(Math.abs(x) - e.centre_mm[0], y - e.centre_mm[1] - 6, 14, 5));
  const line = h.line_mm - h.drop_mm * (x / h.side_x_mm) ** 2;
  const hair = Math.max(smooth(line - 5, line + 5, y),
                        smooth(h.side_x_mm - 9, h.side_x_mm + 3, Math.abs(x)) * smooth(h.side_y_mm - 4, h.side_y_mm + 12, y));
  return mix(c, HAIR, hair);
}

class Builder {
  constructor() { this.rest = []; this.col = []; this.uv = []; this.z = []; this.layers = {}; this.tris = []; this.lines = []; }
  get n() { return this.rest.length / 2; }
  add(x, y, col, uv = [0, 0], z = null) {
    this.rest.push(x, y); this.col.push(...col); this.uv.push(...uv);
    this.z.push(z === null ? faceDepth(x, y) : z);
    return this.n - 1;
  }
  layer(name, fn) {          // triangles added inside fn belong to layer `name` (index range)
    const first = this.tris.length; fn();
    this.layers[name] = { first, count: this.tris.length - first };
  }
  tri(a, b, c) { this.tris.push(a, b, c); }
  quad(a, b, c, d) { this.tris.push(a, b, c, a, c, d); }
  line(a, b) { this.lines.push(a, b); }
  fan(cx, cy, rx, ry, n, col, edge = col) {   // a filled ellipse: centre + ring
    const c = this.add(cx, cy, col), ring = [];
    for (let i = 0; i < n; i++) {
      const t = (2 * Math.PI * i) / n;
      ring.push(this.add(cx + rx * Math.cos(t), cy + ry * Math.sin(t), edge));
    }
    for (let i = 0; i < n; i++) { this.tri(c, ring[i], ring[(i + 1) % n]); this.line(ring[i], ring[(i + 1) % n]); }
    return [c, ring];
  }
}

// Build the face around the server's mouth mesh (GET /mesh JSON).
export function buildFace(mouth) {
  const B = new Builder();
  const H = LAYOUT.head;
  const wire = { skin: [], features: [], lips: [] };

  // body: neck and shoulders, behind the head
  B.layer("body", () => {
    const neck = [[-34, -20], [34, -20], [37, -112], [-37, -112]].map(([x, y]) => B.add(x, y, [0.8, 0.6, 0.48], [0, 0], 30));
    B.quad(...neck);
    const shirt = [[-40, -100], [40, -100], [125, -140], [140, -175], [-140, -175], [-125, -140]]
      .map(([x, y]) => B.add(x, y, [0.24, 0.33, 0.47], [0, 0], 40));
    const collar = B.add(0, -122, [0.8, 0.6, 0.48], [0, 0], 40);
    B.tri(shirt[0], collar, shirt[1]);
    B.quad(shirt[1], shirt[2], shirt[3], shirt[4]); B.quad(shirt[1], shirt[4], shirt[5], shirt[0]);
  });

  // skin: a grid over the head outline, denser nowhere (DECface's was hand-made; ours is
  // a warped rectangle so every row spans the head at its height)
  const grid0 = B.n;
  for (let j = 0; j < ROWS; j++) {
    const y = H.bottom_mm + ((H.top_mm - H.bottom_mm) * j) / (ROWS - 1);
    const hw = headHalfWidth(y);
    for (let i = 0; i < COLS; i++) {
      const x = hw * (-1 + (2 * i) / (COLS - 1));
      B.add(x, y, skinColour(x, y), faceUV(x, y));
    }
  }
  const g = (i, j) => grid0 + j * COLS + i;
  B.layer("skin", () => {
    for (let j = 0; j + 1 < ROWS; j++) for (let i = 0; i + 1 < COLS; i++) B.quad(g(i, j), g(i + 1, j), g(i + 1, j + 1), g(i, j + 1));
  });
  for (let j = 0; j < ROWS; j++) for (let i = 0; i < COLS; i++) {
    if (i + 1 < COLS) wire.skin.push(g(i, j), g(i + 1, j));
    if (j + 1 < ROWS) wire.skin.push(g(i, j), g(i, j + 1));
    if (i + 1 < COLS && j + 1 < ROWS) wire.skin.push(g(i, j), g(i + 1, j + 1));
  }
  const outline = [];
  for (let i = 0; i < COLS; i++) outline.push(g(i, 0));
  for (let j = 1; j < ROWS; j++) outline.push(g(COLS - 1, j));
  for (let i = COLS - 2; i >= 0; i--) outline.push(g(i, ROWS - 1));
  for (let j = ROWS - 2; j > 0; j--) outline.push(g(0, j));

  // mouth nodes, then their cavity copy
  const names = mouth.nodes, N = names.length, idx = Object.fromEntries(names.map((n, i) => [n, i]));
  const node0 = B.n;
  for (let i = 0; i < N; i++) {
    const [x, y] = mouth.rest[i], nm = names[i];
    const upper = nm.includes("upper"), inner = nm.startsWith("inner");
    const col = mix(upper ? mix(LIP, [0.5, 0.2, 0.22], 0.25) : LIP, [0.42, 0.14, 0.16], inner ? 0.55 : 0);
    B.add(x, y, nm.startsWith("corner") ? mix(LIP, [0.4, 0.15, 0.15], 0.5) : col, lipsUV(x, y), faceDepth(x, y) + 3);
  }
  const cav0 = B.n;
  for (let i = 0; i < N; i++) {
    const [x, y] = mouth.rest[i], nm = names[i];
    B.add(x, y, nm.includes("lower") ? [0.45, 0.14, 0.15] : [0.16, 0.04, 0.05], [0, 0], 0);
  }
  const region = (r) => (mouth.regions && mouth.regions[r]) || [];
  const cavitySet = new Set(region("cavity"));
  B.layer("lips", () => mouth.triangles.forEach((t, k) => { if (!cavitySet.has(k)) B.tri(node0 + t[0], node0 + t[1], node0 + t[2]); }));
  B.layer("cavity", () => mouth.triangles.forEach((t, k) => { if (cavitySet.has(k)) B.tri(cav0 + t[0], cav0 + t[1], cav0 + t[2]); }));
  for (const [a, b] of mouth.edges) wire.lips.push(node0 + a, node0 + b);
  for (const t of mouth.triangles) wire.lips.push(node0 + t[0], node0 + t[1], node0 + t[1], node0 + t[2], node0 + t[2], node0 + t[0]);

  // teeth: each tooth its own quad (gaps between them read as teeth), greyer toward the
  // sides, which curve back into the mouth. Upper teeth hang from the upper teeth edge,
  // lower ones stand on the lower edge; rows are placed each frame.
  const teeth = [];
  const toothRow = (bounds, upper) => {
    for (const s of [-1, 1]) for (let k = 0; k + 1 < bounds.length; k++) {
      const xa = s * (bounds[k] + (k ? 0.35 : 0.2)), xb = s * (bounds[k + 1] - 0.35);
      const shade = 0.97 - 0.09 * k, tip = [shade, shade * 0.98, shade * 0.93], root = mix(tip, [0.75, 0.55, 0.5], 0.25);
      const vs = [[xa, 0, tip], [xb, 0, tip], [xb, 1, root], [xa, 1, root]].map(([x, r, c]) => {
        const v = B.add(x, 0, c, [0, 0], 0);
        teeth.push({ v, x, root: r, upper, len: upper ? 11 - 0.6 * k : 10 - 0.5 * k, curve: 0.004 * x * x });
        return v;
      });
      B.quad(...vs);
    }
  };
  B.layer("teeth", () => { toothRow([0, 8.4, 15, 21, 25.5, 29], true); toothRow([0, 5.4, 10.8, 16.5, 21.5, 26], false); });

  // eyes: 9 columns from the inner to the outer corner
  const E = LAYOUT.eyes, EC = 9, eyes = [];
  for (const s of [-1, 1]) {
    const [ex, ey] = [s * E.centre_mm[0], E.centre_mm[1]];
    const eye = { fold: [], lid: [], lower: [], lash: [], upperY: [], closedY: [], lashH: [] };
    for (let i = 0; i < EC; i++) {
      const u = -1 + (2 * i) / (EC - 1), x = ex + s * u * E.half_width_mm, b = Math.pow(1 - u * u, 0.7);
      const tilt = 1.2 * u;            // outer corners sit a little higher
      const up = ey + tilt + E.upper_mm * b - 0.6 * u, lo = ey + tilt - E.lower_mm * b;
      eye.upperY.push(up); eye.closedY.push(lo + 0.2 * (up - lo)); eye.lashH.push(0.5 + 1.4 * Math.sqrt(1 - u * u));
      const fold = ey + tilt + E.fold_mm * Math.pow(1 - 0.8 * u * u, 0.8);
      eye.fold.push(B.add(x, fold, mix(SKIN, [0.8, 0.58, 0.5], 0.5), faceUV(x, fold)));
      eye.lid.push(B.add(x, up, mix(SKIN, [0.78, 0.55, 0.48], 0.6), faceUV(x, up)));
      const sclera = mix([0.97, 0.96, 0.94], [0.85, 0.66, 0.64], Math.abs(u) ** 3);
      eye.lower.push(B.add(x, lo, sclera));
      eye.lash.push(B.add(x, up + eye.lashH[i], [0.13, 0.09, 0.08]));
    }
    eye.sclera = [];   // the white, whose top follows the lid
    for (let i = 0; i < EC; i++) {
      const u = -1 + (2 * i) / (EC - 1);
      eye.sclera.push(B.add(B.rest[2 * eye.lid[i]], eye.upperY[i], mix([0.97, 0.96, 0.94], [0.85, 0.66, 0.64], Math.abs(u) ** 3)));
    }
    eyes.push({ ...eye, cx: ex, cy: ey });
  }
  B.layer("sclera", () => { for (const e of eyes) for (let i = 0; i + 1 < EC; i++) B.quad(e.sclera[i], e.sclera[i + 1], e.lower[i + 1], e.lower[i]); });
  B.layer("iris", () => {
    for (const e of eyes) {
      B.fan(e.cx, e.cy - 0.4, E.iris_mm, E.iris_mm, 20, [0.36, 0.52, 0.62], [0.16, 0.25, 0.33]);
      B.fan(e.cx, e.cy - 0.4, E.pupil_mm, E.pupil_mm, 14, [0.03, 0.03, 0.04]);
      B.fan(e.cx - 1.8, e.cy + 1.4, 0.9, 0.9, 8, [1, 1, 1]);
    }
  });
  B.layer("lids", () => { for (const e of eyes) for (let i = 0; i + 1 < EC; i++) B.quad(e.fold[i], e.fold[i + 1], e.lid[i + 1], e.lid[i]); });
  B.layer("lashes", () => { for (const e of eyes) for (let i = 0; i + 1 < EC; i++) B.quad(e.lid[i], e.lid[i + 1], e.lash[i + 1], e.lash[i]); });
  for (const e of eyes) for (let i = 0; i + 1 < EC; i++) {
    wire.features.push(e.fold[i], e.fold[i + 1], e.lid[i], e.lid[i + 1], e.lower[i], e.lower[i + 1]);
  }

  // brows: a tapered strip along a curve through inner, peak and outer points
  const BR = LAYOUT.brows, BC = 9, brows = [];
  B.layer("brows", () => {
    for (const s of [-1, 1]) {
      const top = [], bot = [];
      for (let i = 0; i < BC; i++) {
        const t = i / (BC - 1);
        const q = (k) => (1 - t) * (1 - t) * BR.inner_mm[k] + 2 * t * (1 - t) * (2 * BR.peak_mm[k] - (BR.inner_mm[k] + BR.outer_mm[k]) / 2) + t * t * BR.outer_mm[k];
        const x = s * q(0), y = q(1), th = BR.thick_inner_mm + (BR.thick_outer_mm - BR.thick_inner_mm) * t;
        const c = [0.3, 0.2, 0.14];
        top.push(B.add(x, y + th / 2, c)); bot.push(B.add(x + s * 0.6 * t, y - th / 2, c));
      }
      for (let i = 0; i + 1 < BC; i++) { B.quad(top[i], top[i + 1], bot[i + 1], bot[i]); wire.features.push(top[i], top[i + 1], bot[i], bot[i + 1]); }
      brows.push(...top, ...bot);
    }
  });

  // nostrils
  const nostrils = [];
  B.layer("nostrils", () => {
    const n = LAYOUT.nose;
    for (const s of [-1, 1]) {
      const [c, ring] = B.fan(s * n.nostril_mm[0], n.nostril_mm[1], n.nostril_r_mm[0], n.nostril_r_mm[1], 10, [0.3, 0.14, 0.12], [0.55, 0.33, 0.28]);
      nostrils.push(c, ...ring);
    }
  });
  wire.features.push(...B.lines);

  const rest = Float32Array.from(B.rest), nv = B.n;
  const skinIdx = Array.from({ length: ROWS * COLS }, (_, k) => grid0 + k);
  const lipNodes = names.map((nm, i) => (/^(corner|outer|inner)/.test(nm) ? node0 + i : -1)).filter((v) => v >= 0);
  const foldIdx = eyes.flatMap((e) => e.fold);
  const muscles = buildMuscles(rest, [...skinIdx, ...lipNodes, ...brows, ...nostrils, ...foldIdx]);

  // skin <- lip nodes: inverse-distance weights to the driver nodes, faded out by the
  // distance to the nearest one, so the influence stays local to the mouth
  const drv = DRIVERS.map((d) => idx[d]);
  const follow = [], wts = [];
  for (const v of skinIdx) {
    const x = rest[2 * v], y = rest[2 * v + 1];
    const d2 = drv.map((j) => (x - mouth.rest[j][0]) ** 2 + (y - mouth.rest[j][1]) ** 2);
    const A = 1 - smooth(0, 34, Math.sqrt(Math.min(...d2)));
    if (A <= 0) continue;
    const inv = d2.map((d) => 1 / (d + 4)), sum = inv.reduce((a, b) => a + b, 0);
    follow.push(v); wts.push(...inv.map((w) => (A * w) / sum));
  }
  const jawW = new Float32Array(nv);
  for (const v of skinIdx) jawW[v] = jawWeight(rest[2 * v], rest[2 * v + 1]);

  const lines = (arr) => Uint16Array.from(arr);
  return {
    nv, rest, z: Float32Array.from(B.z), col: Float32Array.from(B.col), uv: Float32Array.from(B.uv),
    tris: Uint16Array.from(B.tris), layers: B.layers,
    wire: { skin: lines(wire.skin), features: lines(wire.features), lips: lines(wire.lips) },
    nodeIdx: Uint16Array.from({ length: N }, (_, i) => node0 + i),
    names, node0, cav0, N, idx, grid0, gridN: ROWS * COLS, outline, eyes, teeth, brows, nostrils,
    muscles, drv: Int32Array.from(drv), follow: Int32Array.from(follow), wts: Float32Array.from(wts), jawW,
    mouthRest: Float32Array.from(mouth.rest.flat()),
    litTris: (() => { const L = B.layers, a = []; for (const k of ["skin", "lips"]) a.push(...B.tris.slice(L[k].first, L[k].first + L[k].count)); return Uint16Array.from(a); })(),
  };
}

// Deforms a built face into `pos` (Float32Array, 2 per vertex) and `nrm` (3 per vertex).
// No allocation per frame: every scratch array is made here.
export class Rig {
  constructor(face) {
    this.f = face;
    this.pos = new Float32Array(face.rest);
    this.nrm = new Float32Array(face.nv * 3);
    this.resid = new Float32Array(face.drv.length * 2);
    this.input = new Float32Array(face.N * 2);
    this._names = null; this._map = null;
    this.lipGap = 0;
    this._staticNormals();
  }

  _staticNormals() {           // from the depth field's slope at rest: for parts never re-lit
    const f = this.f, e = 0.5;
    for (let v = 0; v < f.nv; v++) {
      const x = f.rest[2 * v], y = f.rest[2 * v + 1];
      const dx = (faceDepth(x + e, y) - faceDepth(x - e, y)) / (2 * e), dy = (faceDepth(x, y + e) - faceDepth(x, y - e)) / (2 * e);
      const l = Math.hypot(dx, dy, 1);
      this.nrm[3 * v] = -dx / l; this.nrm[3 * v + 1] = -dy / l; this.nrm[3 * v + 2] = 1 / l;
    }
    this.staticNrm = new Float32Array(this.nrm);
  }

  // mouth: {names, nodes} from client.mouthAt(), or null for rest; expr: {smile, brow, frown}
  update(mouth, expr, blink) {
    const f = this.f, p = this.pos, rest = f.rest, N = f.N, inp = this.input;
    if (mouth && mouth.nodes) {
      if ((mouth.names || f.names) !== this._names) {   // map the stream's node order onto ours, once
        this._names = mouth.names || f.names;
        this._map = Int32Array.from(f.names, (n) => (mouth.names ? mouth.names.indexOf(n) : f.idx[n]));
      }
      for (let i = 0; i < N; i++) {
        const k = this._map[i] >= 0 ? this._map[i] : i, q = mouth.nodes[k];
        if (q) { inp[2 * i] = q[0]; inp[2 * i + 1] = q[1]; } else { inp[2 * i] = f.mouthRest[2 * i]; inp[2 * i + 1] = f.mouthRest[2 * i + 1]; }
      }
    } else inp.set(f.mouthRest);
    p.set(rest);
    const chin = f.idx.chin;
    const jawDy = inp[2 * chin + 1] - f.mouthRest[2 * chin + 1];
    // residual motion of the driver nodes once the jaw's share is taken out
    for (let k = 0; k < f.drv.length; k++) {
      const j = f.drv[k], x = f.mouthRest[2 * j], y = f.mouthRest[2 * j + 1];
      this.resid[2 * k] = inp[2 * j] - x;
      this.resid[2 * k + 1] = inp[2 * j + 1] - y - jawWeight(x, y) * jawDy;
    }
    for (let v = f.grid0, end = f.grid0 + f.gridN; v < end; v++) p[2 * v + 1] += f.jawW[v] * jawDy;
    const D = f.drv.length;
    for (let a = 0; a < f.follow.length; a++) {
      const v = f.follow[a];
      let dx = 0, dy = 0;
      for (let k = 0; k < D; k++) { const w = f.wts[a * D + k]; dx += w * this.resid[2 * k]; dy += w * this.resid[2 * k + 1]; }
      p[2 * v] += dx; p[2 * v + 1] += dy;
    }
    for (let i = 0; i < N; i++) { p[2 * (f.node0 + i)] = inp[2 * i]; p[2 * (f.node0 + i) + 1] = inp[2 * i + 1]; }
    applyMuscles(f.muscles, expr, p);
    // lips must not cross: a lower inner lip node never rises above its upper partner
    let gap = 0;
    for (let k = 0; k < 5; k++) {
      const u = f.node0 + f.idx[`inner_upper_${k}`], l = f.node0 + f.idx[`inner_lower_${k}`];
      if (p[2 * l + 1] > p[2 * u + 1]) { const m = (p[2 * l + 1] + p[2 * u + 1]) / 2; p[2 * l + 1] = m; p[2 * u + 1] = m; }
      gap += p[2 * u + 1] - p[2 * l + 1];
    }
    this.lipGap = gap / 5;      // measured on the drawn vertices
    for (let i = 0; i < N; i++) { p[2 * (f.cav0 + i)] = p[2 * (f.node0 + i)]; p[2 * (f.cav0 + i) + 1] = p[2 * (f.node0 + i) + 1]; }
    // teeth: upper row hangs from the upper teeth edge; lower row rides the jaw
    const tu = inp[2 * f.idx.teeth_upper_c + 1], tl = inp[2 * f.idx.teeth_lower_c + 1];
    for (const t of f.teeth) {
      const edge = t.upper ? tu + t.curve : tl - t.curve;
      p[2 * t.v + 1] = edge + (t.upper ? 1 : -1) * t.root * t.len;
    }
    // blink: the lid edge (and the white's top) slides toward the closed line
    for (const e of f.eyes) for (let i = 0; i < e.lid.length; i++) {
      const y = e.upperY[i] + (e.closedY[i] - e.upperY[i]) * blink;
      p[2 * e.lid[i] + 1] = y; p[2 * e.sclera[i] + 1] = y; p[2 * e.lash[i] + 1] = y + e.lashH[i] * (1 - 0.6 * blink);
    }
    this._normals();
  }

  _normals() {                   // Gouraud normals of the deformed skin and lips
    const f = this.f, p = this.pos, n = this.nrm, z = f.z, t = f.litTris;
    const a0 = f.grid0, a1 = f.node0 + f.N;
    n.fill(0, 3 * a0, 3 * a1);
    for (let k = 0; k < t.length; k += 3) {
      const a = t[k], b = t[k + 1], c = t[k + 2];
      const ux = p[2 * b] - p[2 * a], uy = p[2 * b + 1] - p[2 * a + 1], uz = z[b] - z[a];
      const vx = p[2 * c] - p[2 * a], vy = p[2 * c + 1] - p[2 * a + 1], vz = z[c] - z[a];
      let nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
      if (nz < 0) { nx = -nx; ny = -ny; nz = -nz; }
      n[3 * a] += nx; n[3 * a + 1] += ny; n[3 * a + 2] += nz;
      n[3 * b] += nx; n[3 * b + 1] += ny; n[3 * b + 2] += nz;
      n[3 * c] += nx; n[3 * c + 1] += ny; n[3 * c + 2] += nz;
    }
    for (let v = a0; v < a1; v++) if (n[3 * v + 2] === 0) { n[3 * v] = this.staticNrm[3 * v]; n[3 * v + 1] = this.staticNrm[3 * v + 1]; n[3 * v + 2] = this.staticNrm[3 * v + 2]; }
  }

  // The mouth nodes as drawn: [[x, y], ...] in GET /mesh order (allocates: for tests/tools).
  nodePositions() {
    const f = this.f;
    return Array.from({ length: f.N }, (_, i) => [this.pos[2 * (f.node0 + i)], this.pos[2 * (f.node0 + i) + 1]]);
  }
}
