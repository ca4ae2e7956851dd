// Canvas 2-D fallback for browsers without WebGL. Same mesh and rig; instead of shading
// thousands of triangles (slow in 2-D) it fills a few outlines taken from the deformed
// mesh: head, lips, cavity, teeth, eyes, brows. "textured" draws the face image, with
// the part below the mouth redrawn lower by the jaw's drop, and the lips from the atlas.

import { LAYOUT } from "./layout.js";
import { VIEW } from "./gl.js";

export const C2D_LOOKS = ["wireframe", "shaded", "textured"];
const rgb = (c) => `rgb(${Math.round(c[0] * 255)},${Math.round(c[1] * 255)},${Math.round(c[2] * 255)})`;

export class Canvas2DRenderer {
  constructor(canvas, ctx, face, image) {
    this.canvas = canvas; this.ctx = ctx; this.f = face; this.image = image;
    const n = (name) => face.node0 + face.idx[name];
    const row = (p) => [0, 1, 2, 3, 4].map((i) => n(`${p}_${i}`));
    const L = n("corner_l"), R = n("corner_r");
    this.upperLip = [L, ...row("outer_upper"), R, ...row("inner_upper").reverse()];
    this.lowerLip = [L, ...row("inner_lower"), R, ...row("outer_lower").reverse()];
    this.cavity = [L, ...row("inner_upper"), R, ...row("inner_lower").reverse()];
    this.jawLine = face.outline.filter((v) => face.rest[2 * v + 1] < -2);
    this.teethQuads = [];
    for (let k = 0; k < face.teeth.length; k += 4) this.teethQuads.push([0, 1, 2, 3].map((j) => face.teeth[k + j].v));
    const half = face.brows.length / 4;   // per brow: top points, then bottom points
    this.browPolys = [0, 1].map((b) => {
      const top = face.brows.slice(b * 2 * half, b * 2 * half + half), bot = face.brows.slice(b * 2 * half + half, (b + 1) * 2 * half);
      return [...top, ...bot.reverse()];
    });
  }

  render(rig, look) {
    const c = this.canvas, ctx = this.ctx, f = this.f, p = rig.pos;
    const s = Math.min(c.width / VIEW.w, c.height / VIEW.h), ox = c.width / 2, oy = c.height / 2;
    const X = (v) => ox + (p[2 * v] - VIEW.cx) * s, Y = (v) => oy - (p[2 * v + 1] - VIEW.cy) * s;
    const path = (vs) => { ctx.beginPath(); ctx.moveTo(X(vs[0]), Y(vs[0])); for (let i = 1; i < vs.length; i++) ctx.lineTo(X(vs[i]), Y(vs[i])); ctx.closePath(); };
    const fill = (vs, col) => { path(vs); ctx.fillStyle = col; ctx.fill(); };
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = look === "wireframe" ? "#0a0f12" : "#20252b";
    ctx.fillRect(0, 0, c.width, c.height);
    if (look === "wireframe") return this._wire(ctx, f, X, Y, path, s);

    // body: buildFace() makes it first, so vertices 0-3 are the neck, 4-9 the shirt
    fill([0, 1, 2, 3], rgb([0.8, 0.6, 0.48]));
    fill([4, 5, 6, 7, 8, 9], rgb([0.24, 0.33, 0.47]));
    // head
    const img = look === "textured" && this.image;
    if (img) {
      const [x0, y0, x1, y1] = LAYOUT.texture.face_box_mm, sw = LAYOUT.texture.size_px[0], sh = LAYOUT.texture.atlas_top_px;
      const dx = ox + (x0 - VIEW.cx) * s, dy = oy - (y1 - VIEW.cy) * s, dw = (x1 - x0) * s, dh = (y1 - y0) * s;
      ctx.save(); path(f.outline); ctx.clip();
      ctx.drawImage(img, 0, 0, sw, sh, dx, dy, dw, dh);
      const jawDy = p[2 * (f.node0 + f.idx.chin) + 1] - f.mouthRest[2 * f.idx.chin + 1];
      if (jawDy < -0.2) {          // redraw the lower face lower by the jaw's drop
        path(this.jawLine); ctx.clip();
        ctx.drawImage(img, 0, 0, sw, sh, dx, dy - jawDy * s, dw, dh);
      }
      ctx.restore();
    } else {
      path(f.outline);
      const g = ctx.createRadialGradient(ox - 15 * s, oy - (70 - VIEW.cy) * s, 10 * s, ox, oy - (40 - VIEW.cy) * s, 110 * s);
      g.addColorStop(0, "#f6d2b6"); g.addColorStop(1, "#c98f6e");
      ctx.fillStyle = g; ctx.fill();
      ctx.save(); path(f.outline); ctx.clip();
      const h = LAYOUT.hair;
      ctx.beginPath();
      ctx.moveTo(ox - 100 * s, oy - (h.side_y_mm - VIEW.cy) * s);
      for (let x = -h.side_x_mm; x <= h.side_x_mm; x += 4) ctx.lineTo(ox + x * s, oy - (h.line_mm - h.drop_mm * (x / h.side_x_mm) ** 2 - VIEW.cy) * s);
      ctx.lineTo(ox + 100 * s, oy - (h.side_y_mm - VIEW.cy) * s); ctx.lineTo(ox + 100 * s, 0); ctx.lineTo(ox - 100 * s, 0); ctx.closePath();
      ctx.fillStyle = "#402a1c"; ctx.fill();
      for (const sx of [-1, 1]) {       // cheeks
        const cx = ox + sx * 40 * s, cy = oy - (22 - VIEW.cy) * s, rg = ctx.createRadialGradient(cx, cy, 0, cx, cy, 16 * s);
        rg.addColorStop(0, "rgba(230,130,120,0.45)"); rg.addColorStop(1, "rgba(230,130,120,0)");
        ctx.fillStyle = rg; ctx.fillRect(cx - 16 * s, cy - 16 * s, 32 * s, 32 * s);
      }
      ctx.restore();
      for (let k = 0; k < f.nostrils.length; k += 11) fill(f.nostrils.slice(k + 1, k + 11), "#6b3328");
      for (const b of this.browPolys) fill(b, "#4d3324");
    }
    // mouth: cavity, teeth clipped to it, lips over
    fill(this.cavity, "#3a0f12");
    ctx.save(); path(this.cavity); ctx.clip();
    for (const q of this.teethQuads) fill(q, rgb(f.col.subarray(3 * q[0], 3 * q[0] + 3)));
    ctx.restore();
    if (img) this._lipsFromAtlas(ctx, rig, X, Y, path, s);
    else { fill(this.upperLip, "#a4484f"); fill(this.lowerLip, "#c25a60"); }
    // eyes
    for (const e of f.eyes) {
      const white = [...e.sclera, ...[...e.lower].reverse()];
      fill(white, "#f4f2ee");
      ctx.save(); path(white); ctx.clip();
      const ix = ox + (e.cx - VIEW.cx) * s, iy = oy - (e.cy - 0.4 - VIEW.cy) * s;
      ctx.fillStyle = "#4f7187"; ctx.beginPath(); ctx.arc(ix, iy, LAYOUT.eyes.iris_mm * s, 0, 7); ctx.fill();
      ctx.fillStyle = "#080809"; ctx.beginPath(); ctx.arc(ix, iy, LAYOUT.eyes.pupil_mm * s, 0, 7); ctx.fill();
      ctx.restore();
      fill([...e.fold, ...[...e.lid].reverse()], img ? "#d9a487" : "#d8a488");
      ctx.beginPath(); ctx.moveTo(X(e.lid[0]), Y(e.lid[0]));
      for (const v of e.lid) ctx.lineTo(X(v), Y(v));
      ctx.strokeStyle = "#21160f"; ctx.lineWidth = 1.3 * s; ctx.stroke();
    }
  }

  _lipsFromAtlas(ctx, rig, X, Y, path, s) {
    const f = this.f, T = LAYOUT.texture, [lx0, ly0, lx1, ly1] = T.lips_box_mm, [px0, py0, px1, py1] = T.lips_px;
    // map the lips box by the corners' and midline's motion: a scale and shift of the atlas
    const cl = f.node0 + f.idx.corner_l, cr = f.node0 + f.idx.corner_r;
    const restW = f.mouthRest[2 * f.idx.corner_r] - f.mouthRest[2 * f.idx.corner_l];
    for (const [poly, top, bot] of [[this.upperLip, "outer_upper_2", "inner_upper_2"], [this.lowerLip, "inner_lower_2", "outer_lower_2"]]) {
      const t = f.idx[top], b = f.idx[bot];
      const restH = f.mouthRest[2 * t + 1] - f.mouthRest[2 * b + 1], nowH = rig.pos[2 * (f.node0 + t) + 1] - rig.pos[2 * (f.node0 + b) + 1];
      const sx = (X(cr) - X(cl)) / (restW * s), sy = nowH / Math.max(0.5, restH);
      const midX = (X(cl) + X(cr)) / 2, restMidY = (f.mouthRest[2 * t + 1] + f.mouthRest[2 * b + 1]) / 2;
      const nowMidY = (Y(f.node0 + t) + Y(f.node0 + b)) / 2;
      ctx.save(); path(poly); ctx.clip();
      ctx.translate(midX, nowMidY); ctx.scale(sx, sy); ctx.translate(0, restMidY * s);
      ctx.drawImage(this.image, px0, py0, px1 - px0, py1 - py0, lx0 * s, -ly1 * s, (lx1 - lx0) * s, (ly1 - ly0) * s);
      ctx.restore();
    }
  }

  _wire(ctx, f, X, Y, path, s) {
    path(this.cavity); ctx.fillStyle = "#1f080a"; ctx.fill();
    const lines = (arr, col, w) => {
      ctx.beginPath();
      for (let k = 0; k < arr.length; k += 2) { ctx.moveTo(X(arr[k]), Y(arr[k])); ctx.lineTo(X(arr[k + 1]), Y(arr[k + 1])); }
      ctx.strokeStyle = col; ctx.lineWidth = w; ctx.stroke();
    };
    lines(f.wire.skin, "#1a6150", 1); lines(f.wire.features, "#66d9b3", 1); lines(f.wire.lips, "#ff8c73", 1.5);
    ctx.fillStyle = "#fff27f";
    const r = Math.max(1.5, 0.7 * s);
    ctx.beginPath();
    for (const v of f.nodeIdx) ctx.rect(X(v) - r, Y(v) - r, 2 * r, 2 * r);
    ctx.fill();
  }
}
