// A frontal 2-D face whose mouth is the streamed node mesh (canvas 2-D).
// Node names come from the server (viseme_tables / face/shape.py); coordinates are mm,
// y up, origin at the mouth centre.

const order = (prefix, n) => Array.from({ length: n }, (_, i) => `${prefix}_${i}`);

export function drawFace(ctx, w, h, mouth, opts = {}) {
  const scale = Math.min(w, h) / 160;       // mm -> px
  const cx = w / 2, cy = h * 0.66;
  const P = (p) => [cx + p[0] * scale, cy - p[1] * scale];
  ctx.clearRect(0, 0, w, h);
  // head
  ctx.fillStyle = "#f1c9a5";
  ctx.beginPath();
  ctx.ellipse(w / 2, h * 0.5, 62 * scale, 78 * scale, 0, 0, Math.PI * 2);
  ctx.fill();
  // eyes (blink)
  const blink = opts.blink ? 0.1 : 1;
  ctx.fillStyle = "#2b2b2b";
  for (const sx of [-1, 1]) {
    ctx.beginPath();
    ctx.ellipse(w / 2 + sx * 24 * scale, h * 0.4, 6 * scale, 4 * scale * blink, 0, 0, Math.PI * 2);
    ctx.fill();
  }
  if (!mouth) {             // at rest: closed lips
    ctx.strokeStyle = "#b5495b"; ctx.lineWidth = 5 * scale;
    ctx.beginPath(); ctx.moveTo(cx - 25 * scale, cy); ctx.quadraticCurveTo(cx, cy + 3 * scale, cx + 25 * scale, cy); ctx.stroke();
    return;
  }
  const byName = new Map(mouth.names.map((n, i) => [n, mouth.nodes[i]]));
  const get = (n) => byName.get(n);
  const contour = (names) => names.map(get).filter(Boolean).map(P);
  const outer = [get("corner_l"), ...order("outer_upper", 5).map(get), get("corner_r"),
                 ...order("outer_lower", 5).reverse().map(get)].filter(Boolean).map(P);
  const inner = [get("corner_l"), ...order("inner_upper", 5).map(get), get("corner_r"),
                 ...order("inner_lower", 5).reverse().map(get)].filter(Boolean).map(P);
  const poly = (pts) => { ctx.beginPath(); pts.forEach((p, i) => i ? ctx.lineTo(...p) : ctx.moveTo(...p)); ctx.closePath(); };
  ctx.fillStyle = "#b5495b"; poly(outer); ctx.fill();
  ctx.fillStyle = "#3a1010"; poly(inner); ctx.fill();
  ctx.save(); poly(inner); ctx.clip();
  ctx.fillStyle = "#fafafa";
  const tu = contour(["teeth_upper_l", "teeth_upper_c", "teeth_upper_r"]);
  const tl = contour(["teeth_lower_l", "teeth_lower_c", "teeth_lower_r"]);
  if (tu.length === 3) ctx.fillRect(tu[0][0], tu[0][1] - 6 * scale, tu[2][0] - tu[0][0], 6 * scale);
  if (tl.length === 3) ctx.fillRect(tl[0][0], tl[0][1], tl[2][0] - tl[0][0], 5 * scale);
  ctx.restore();
  if (opts.wireframe) {
    ctx.strokeStyle = "#0a6"; ctx.lineWidth = 1;
    for (const p of mouth.nodes.map(P)) { ctx.beginPath(); ctx.arc(p[0], p[1], 2, 0, 7); ctx.stroke(); }
  }
}
