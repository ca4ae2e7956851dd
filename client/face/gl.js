// WebGL renderer for the face mesh: one program, one position/normal upload per frame,
// one draw call per layer. The stencil buffer clips teeth to the mouth opening (1) and
// the iris to the eye's white (2), so neither needs clipping geometry on the CPU.

export const VIEW = { cx: 0, cy: 12, w: 215, h: 310 };   // mm of the face shown, fit to the canvas

const VS = `
attribute vec2 aPos; attribute vec3 aNrm; attribute vec3 aCol; attribute vec2 aUV;
uniform vec2 uScale; uniform vec2 uCentre; uniform float uPoint;
varying vec3 vCol; varying vec2 vUV; varying float vShade;
void main() {
  gl_Position = vec4((aPos - uCentre) * uScale, 0.0, 1.0);
  gl_PointSize = uPoint;
  vec3 L = normalize(vec3(-0.35, 0.5, 0.8));
  // Lambert, scaled so a surface facing the viewer keeps its colour
  vShade = 0.35 + 0.65 * max(dot(normalize(aNrm), L), 0.0) / 0.8;
  vCol = aCol; vUV = aUV;
}`;

const FS = `
precision mediump float;
uniform sampler2D uTex; uniform float uTexMix; uniform float uLit; uniform vec4 uFlat;
varying vec3 vCol; varying vec2 vUV; varying float vShade;
void main() {
  vec3 base = mix(vCol, texture2D(uTex, vUV).rgb, uTexMix);
  vec3 c = base * mix(1.0, vShade, uLit);
  gl_FragColor = vec4(mix(c, uFlat.rgb, uFlat.a), 1.0);
}`;

// Each look is its layers in draw order. tex: sample the face texture; lit: how much
// lighting; flat: one colour [r,g,b]; write/test: stencil value; prim: "lines" | "points".
const LOOKS = {
  wireframe: {
    clear: [0.04, 0.06, 0.07],
    layers: [
      { name: "cavity", flat: [0.12, 0.03, 0.04] },
      { wire: "skin", flat: [0.1, 0.38, 0.3] },
      { wire: "features", flat: [0.4, 0.85, 0.7] },
      { wire: "lips", flat: [1.0, 0.55, 0.45] },
      { points: "nodes", flat: [1.0, 0.95, 0.5] },
    ],
  },
  shaded: {
    clear: [0.125, 0.145, 0.17],
    layers: [
      { name: "body", lit: 1 }, { name: "skin", lit: 1 },
      { name: "cavity", write: 1 }, { name: "teeth", test: 1 }, { name: "lips", lit: 1 },
      { name: "sclera", write: 2 }, { name: "iris", test: 2 }, { name: "lids", lit: 1 },
      { name: "lashes" }, { name: "brows", lit: 0.6 }, { name: "nostrils" },
    ],
  },
  textured: {
    clear: [0.125, 0.145, 0.17],
    layers: [
      { name: "body", lit: 1 }, { name: "skin", tex: 1, lit: 0.3 },
      { name: "cavity", write: 1 }, { name: "teeth", test: 1 }, { name: "lips", tex: 1, lit: 0.3 },
      { name: "sclera", write: 2 }, { name: "iris", test: 2 }, { name: "lids", tex: 1, lit: 0.3 },
      { name: "lashes" },
    ],
  },
};
export const GL_LOOKS = Object.keys(LOOKS);

export function createGL(canvas, antialias = false) {
  // MSAA off by default: software rasterisers (SwiftShader, GPU-less kiosks) take 2-3x
  // longer per frame with it, and high-dpi screens hide the aliasing anyway.
  // preserveDrawingBuffer keeps the last frame readable (screenshots, toDataURL).
  const opts = { stencil: true, antialias, alpha: false, preserveDrawingBuffer: true };
  return canvas.getContext("webgl", opts) || canvas.getContext("experimental-webgl", opts);
}

export class GLRenderer {
  constructor(canvas, gl, face, image) {
    this.canvas = canvas; this.gl = gl; this.f = face;
    const prog = this.prog = gl.createProgram();
    for (const [type, src] of [[gl.VERTEX_SHADER, VS], [gl.FRAGMENT_SHADER, FS]]) {
      const s = gl.createShader(type);
      gl.shaderSource(s, src); gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error("face shader: " + gl.getShaderInfoLog(s));
      gl.attachShader(prog, s);
    }
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error("face program: " + gl.getProgramInfoLog(prog));
    gl.useProgram(prog);
    this.u = {};
    for (const n of ["uScale", "uCentre", "uPoint", "uTex", "uTexMix", "uLit", "uFlat"]) this.u[n] = gl.getUniformLocation(prog, n);
    const attr = (name, size, data, usage) => {
      const buf = gl.createBuffer(), loc = gl.getAttribLocation(prog, name);
      gl.bindBuffer(gl.ARRAY_BUFFER, buf); gl.bufferData(gl.ARRAY_BUFFER, data, usage);
      gl.enableVertexAttribArray(loc); gl.vertexAttribPointer(loc, size, gl.FLOAT, false, 0, 0);
      return buf;
    };
    this.posBuf = attr("aPos", 2, face.rest, gl.DYNAMIC_DRAW);
    this.nrmBuf = attr("aNrm", 3, new Float32Array(face.nv * 3), gl.DYNAMIC_DRAW);
    attr("aCol", 3, face.col, gl.STATIC_DRAW);
    attr("aUV", 2, face.uv, gl.STATIC_DRAW);
    // one index buffer: triangles, then the wireframe's line lists, then the node points
    const parts = [["tris", face.tris], ["skin", face.wire.skin], ["features", face.wire.features],
                   ["lips", face.wire.lips], ["nodes", face.nodeIdx]];
    const total = parts.reduce((a, [, p]) => a + p.length, 0), all = new Uint16Array(total);
    this.ranges = {};
    let at = 0;
    for (const [k, p] of parts) { all.set(p, at); this.ranges[k] = { first: at, count: p.length }; at += p.length; }
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, all, gl.STATIC_DRAW);
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture());
    if (image) gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, gl.RGB, gl.UNSIGNED_BYTE, image);
    else gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, 1, 1, 0, gl.RGB, gl.UNSIGNED_BYTE, new Uint8Array([237, 190, 158]));
    for (const [k, v] of [[gl.TEXTURE_MIN_FILTER, gl.LINEAR], [gl.TEXTURE_MAG_FILTER, gl.LINEAR],
                          [gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE], [gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE]]) gl.texParameteri(gl.TEXTURE_2D, k, v);
    gl.uniform1i(this.u.uTex, 0);
    gl.disable(gl.DEPTH_TEST); gl.disable(gl.CULL_FACE);
  }

  render(rig, look) {
    const gl = this.gl, L = LOOKS[look], c = this.canvas;
    gl.viewport(0, 0, c.width, c.height);
    const s = Math.min(c.width / VIEW.w, c.height / VIEW.h);   // px per mm
    gl.uniform2f(this.u.uScale, (2 * s) / c.width, (2 * s) / c.height);
    gl.uniform2f(this.u.uCentre, VIEW.cx, VIEW.cy);
    gl.uniform1f(this.u.uPoint, Math.max(3, s * 1.4));
    gl.bindBuffer(gl.ARRAY_BUFFER, this.posBuf);
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, rig.pos);
    if (look !== "wireframe") { gl.bindBuffer(gl.ARRAY_BUFFER, this.nrmBuf); gl.bufferSubData(gl.ARRAY_BUFFER, 0, rig.nrm); }
    gl.clearColor(L.clear[0], L.clear[1], L.clear[2], 1); gl.clearStencil(0);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.STENCIL_BUFFER_BIT);
    for (const ly of L.layers) {
      gl.uniform1f(this.u.uTexMix, ly.tex || 0);
      gl.uniform1f(this.u.uLit, ly.lit || 0);
      if (ly.flat) gl.uniform4f(this.u.uFlat, ly.flat[0], ly.flat[1], ly.flat[2], 1); else gl.uniform4f(this.u.uFlat, 0, 0, 0, 0);
      if (ly.write) { gl.enable(gl.STENCIL_TEST); gl.stencilFunc(gl.ALWAYS, ly.write, 0xff); gl.stencilOp(gl.KEEP, gl.KEEP, gl.REPLACE); }
      else if (ly.test) { gl.enable(gl.STENCIL_TEST); gl.stencilFunc(gl.EQUAL, ly.test, 0xff); gl.stencilOp(gl.KEEP, gl.KEEP, gl.KEEP); }
      else gl.disable(gl.STENCIL_TEST);
      if (ly.name) {
        const r = this.f.layers[ly.name];
        gl.drawElements(gl.TRIANGLES, r.count, gl.UNSIGNED_SHORT, 2 * r.first);
      } else {
        const r = this.ranges[ly.wire || ly.points];
        gl.drawElements(ly.wire ? gl.LINES : gl.POINTS, r.count, gl.UNSIGNED_SHORT, 2 * r.first);
      }
    }
  }
}
