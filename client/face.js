// The talking face (issue #6): a DECface-style mesh (Waters & Levergood 1993) whose mouth
// is the streamed node mesh, with a jaw, teeth, blinking eyes, brows and linear-muscle
// expressions, drawn in WebGL (canvas 2-D when WebGL is missing).
//
//   const face = await createFace(canvas, { look: "textured" });
//   face.setExpression({ smile: 0.5 });
//   const drawn = face.draw(client.mouthAt(sample), performance.now());  // {lipGap, sample, ms, blink}
//
// Parts: face/layout.js (where features are), face/mesh.js (mesh + rig), face/muscles.js
// (the muscle table), face/gl.js and face/canvas2d.js (renderers).

import { buildFace, Rig } from "./face/mesh.js";
import { EXPRESSIONS } from "./face/muscles.js";
import { GLRenderer, GL_LOOKS, createGL } from "./face/gl.js";
import { Canvas2DRenderer, C2D_LOOKS } from "./face/canvas2d.js";

const BLINK_CLOSE_MS = 60, BLINK_OPEN_MS = 90;       // ~150 ms a blink, closing faster
const BLINK_GAP_MS = [2000, 8000];                    // people blink every 2-8 s at rest

function loadImage(url) {
  return new Promise((resolve) => {
    const img = new Image();
    img.onload = () => resolve(img);
    img.onerror = () => { console.warn(`lipclock face: texture ${url} did not load; textured look falls back to colours`); resolve(null); };
    img.src = url;
  });
}

// opts: look (default "textured"), mesh (GET /mesh JSON; fetched when absent),
// meshUrl, textureUrl, random (a () => [0,1) source for blink timing), antialias
// (WebGL MSAA; default off, see face/gl.js).
export async function createFace(canvas, opts = {}) {
  const meshUrl = opts.meshUrl || "/mesh";
  const textureUrl = opts.textureUrl || new URL("./assets/face.png", import.meta.url).href;
  const [mouth, image] = await Promise.all([
    opts.mesh ? Promise.resolve(opts.mesh) : fetch(meshUrl).then((r) => {
      if (!r.ok) throw new Error(`lipclock face: ${meshUrl} answered ${r.status}`);
      return r.json();
    }),
    loadImage(textureUrl),
  ]);
  const face = buildFace(mouth);
  const rig = new Rig(face);
  const gl = createGL(canvas, Boolean(opts.antialias));
  let renderer, backend;
  if (gl) {
    renderer = new GLRenderer(canvas, gl, face, image); backend = "webgl";
  } else {
    renderer = new Canvas2DRenderer(canvas, canvas.getContext("2d"), face, image); backend = "canvas2d";
  }
  const looks = backend === "webgl" ? GL_LOOKS : C2D_LOOKS;
  const random = opts.random || Math.random;
  const expr = { smile: 0, brow: 0, frown: 0 };
  const warned = new Set();
  let look = looks.includes(opts.look) ? opts.look : "textured";
  let blinkAt = null, nextBlink = null;

  function setLook(name) {
    if (looks.includes(name)) { look = name; return; }
    if (!warned.has(name)) { warned.add(name); console.warn(`lipclock face: unknown look ${JSON.stringify(name)}; looks are ${looks.join(", ")}`); }
  }
  if (opts.look !== undefined && !looks.includes(opts.look)) setLook(opts.look);

  function blinkAmount(now) {
    if (nextBlink === null) nextBlink = now + BLINK_GAP_MS[0] * random();
    if (blinkAt === null && now >= nextBlink) blinkAt = now;
    if (blinkAt === null) return 0;
    const t = now - blinkAt;
    if (t >= BLINK_CLOSE_MS + BLINK_OPEN_MS || t < 0) {
      blinkAt = null;
      nextBlink = now + BLINK_GAP_MS[0] + (BLINK_GAP_MS[1] - BLINK_GAP_MS[0]) * random();
      return 0;
    }
    return t < BLINK_CLOSE_MS ? t / BLINK_CLOSE_MS : 1 - (t - BLINK_CLOSE_MS) / BLINK_OPEN_MS;
  }

  function fitCanvas() {            // follow the element's size; reallocates only on change
    const dpr = Math.min(window.devicePixelRatio || 1, 2);
    const w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  }

  const drawn = { lipGap: 0, sample: null, ms: 0 };
  return {
    looks: [...looks],
    backend,
    get look() { return look; },
    setLook,
    setExpression(e) {
      for (const k of EXPRESSIONS) {
        if (e && e[k] !== undefined) { const v = Number(e[k]); if (Number.isFinite(v)) expr[k] = Math.min(1, Math.max(0, v)); }
      }
    },
    get expression() { return { ...expr }; },
    draw(m, nowMs = performance.now()) {
      const t0 = performance.now();
      fitCanvas();
      const blink = blinkAmount(nowMs);
      rig.update(m, expr, blink);
      renderer.render(rig, look);
      drawn.lipGap = rig.lipGap; drawn.sample = m ? m.sample : null;
      drawn.ms = performance.now() - t0;
      return { lipGap: drawn.lipGap, sample: drawn.sample, ms: drawn.ms, blink };
    },
    // debug accessors (tests, tools): the mouth nodes as last drawn, in GET /mesh order
    nodeNames: [...face.names],
    nodePositions() { return rig.nodePositions(); },
    blinkNow() { nextBlink = -Infinity; },
  };
}
