// The 3-D avatar example at /avatar3d: a head built in code with three.js, whose morph
// targets (ARKit and Oculus names) are driven by MorphAdaptor on the audio clock.
// Units: 1 = 100 mm; the face looks along +z, the subject's left is +x.
import { LipclockClient } from "/client/lipclock.js";
import { ARKIT, MorphAdaptor, OCULUS } from "/client/morphs.js";

const $ = (id) => document.getElementById(id);
const client = new LipclockClient({ channel: new URLSearchParams(location.search).get("channel") || "default" });
window.lipclockClient = client;
window.lipclockDebug = { get audioSample() { return client.debug.audioSample; } };

client.addEventListener("open", () => { $("status").textContent = "connected"; });
client.addEventListener("close", () => { $("status").textContent = "reconnecting…"; });
client.addEventListener("server-error", (e) => { $("status").textContent = e.detail.reason; });
client.unlock().then((ok) => { $("unlock").hidden = ok || client.deviceMode; });
$("unlock").onclick = async () => { $("unlock").hidden = await client.unlock(); };
$("speak").onclick = async () => {
  if (!client.deviceMode) $("unlock").hidden = await client.unlock();
  client.speak($("text").value);
};
$("stop").onclick = () => client.stop();

function showError(msg) {
  $("glerror").textContent = msg;
  $("glerror").hidden = false;
}

function webglAvailable() {
  try {
    const c = document.createElement("canvas");
    return !!(c.getContext("webgl2") || c.getContext("webgl"));
  } catch (_) {
    return false;
  }
}

// --- the mouth's geometry and its morph targets -------------------------------------------

const MOUTH_Y = -0.52;       // mouth centre height
const MOUTH_HALF = 0.25;     // half the mouth width at rest (50 mm)
const LIP_SEP = 0.02;        // half the distance between the lips' centre lines at rest
const JAW_HINGE = [MOUTH_Y + 0.45, -0.15];   // (y, z) of the jaw's rotation axis
const JAW_ANGLE = 0.14;      // radians at jawOpen = 1: about 16 mm at the chin
const LID_OPEN = -0.95, LID_SHUT = 0.55;   // eyelid tilt (radians about x)

const smoothstep = (a, b, x) => { const t = Math.min(1, Math.max(0, (x - a) / (b - a))); return t * t * (3 - 2 * t); };
const gauss = (d, s) => Math.exp(-((d / s) ** 2));

// Each vertex of the mouth region carries: its rest position, `lower` (0 = moves with the
// skull, 1 = with the jaw) and its part ("skin", "lip", "cavity", "teeth").
// Where one ARKit target moves it, as [dx, dy, dz] at weight 1. `side` is +1 for *Left.
function arkitDisplacement(name, side, [x, y, z], lower, part) {
  const upper = 1 - lower;
  const rel = y - MOUTH_Y;
  const around = part === "skin" ? gauss(Math.max(0, Math.abs(x) - MOUTH_HALF * 0.8), 0.12) * gauss(rel, 0.1) : 1;
  const lip = part === "teeth" ? 0 : around;              // lip-only motions leave the teeth
  const along = Math.max(0, 1 - (x / MOUTH_HALF) ** 2);    // 1 mid-lip, 0 at the corners
  const onSide = side === 0 ? 1 : smoothstep(-0.08, 0.12, side * x);
  const corner = gauss(x - side * MOUTH_HALF, 0.13) * gauss(rel, 0.12) * (part === "teeth" ? 0.3 : 1);
  switch (name) {
    case "jawOpen": {
      let w = lower;
      if (part === "skin") w = smoothstep(0.01, -0.08, rel) * (1 - smoothstep(0.45, 0.95, Math.abs(x))) * smoothstep(-0.3, 0.3, z);
      const dy0 = y - JAW_HINGE[0], dz0 = z - JAW_HINGE[1];
      const c = Math.cos(JAW_ANGLE), s = Math.sin(JAW_ANGLE);   // rotate the chin down and back
      return [0, w * (dy0 * c - dz0 * s - dy0), w * (dy0 * s + dz0 * c - dz0)];
    }
    case "mouthClose":
      return [0, lip * along * (0.02 * lower - 0.008 * upper), 0];   // against the jaw's drop
    case "mouthFunnel":
      return [-0.3 * x * around, lip * along * (0.035 * upper - 0.035 * lower), 0.06 * around];
    case "mouthPucker":
      return [-0.45 * x * around, lip * along * (0.012 * lower - 0.01 * upper), 0.09 * around];
    case "mouthSmile":
      return [side * 0.035 * corner, 0.045 * corner, -0.015 * corner];
    case "mouthStretch":
      return [side * 0.05 * corner, -0.012 * corner, -0.01 * corner];
    case "mouthRollUpper":
      return [0, -0.015 * upper * lip * along, -0.015 * upper * lip * along];
    case "mouthRollLower":
      return [0, 0.025 * lower * lip * along, -0.02 * lower * lip * along];
    case "mouthPress":
      return [0, lip * along * onSide * (0.015 * lower - 0.01 * upper), -0.004 * lip * along * onSide];
    case "mouthLowerDown":
      return [0, -0.05 * lower * lip * onSide * Math.sqrt(along), 0.01 * lower * lip * onSide];
    case "mouthUpperUp":
      return [0, 0.04 * upper * lip * onSide * Math.sqrt(along), 0.005 * upper * lip * onSide];
    default:
      return [0, 0, 0];
  }
}

// The Oculus visemes, each as a mix of the ARKit targets above (a small viseme table).
const VISEME_RECIPES = {
  viseme_sil: {},
  viseme_PP: { jawOpen: 0.05, mouthClose: 0.6, mouthPress: 0.7, mouthRollUpper: 0.3, mouthRollLower: 0.3 },
  viseme_FF: { jawOpen: 0.1, mouthRollLower: 0.9, mouthUpperUp: 0.4 },
  viseme_TH: { jawOpen: 0.25, mouthLowerDown: 0.3, mouthUpperUp: 0.2 },
  viseme_DD: { jawOpen: 0.3, mouthStretch: 0.2, mouthLowerDown: 0.2 },
  viseme_kk: { jawOpen: 0.4, mouthStretch: 0.15 },
  viseme_CH: { jawOpen: 0.2, mouthFunnel: 0.8, mouthUpperUp: 0.2 },
  viseme_SS: { jawOpen: 0.1, mouthStretch: 0.45, mouthLowerDown: 0.4, mouthUpperUp: 0.4 },
  viseme_nn: { jawOpen: 0.25, mouthLowerDown: 0.2 },
  viseme_RR: { jawOpen: 0.25, mouthFunnel: 0.5 },
  viseme_aa: { jawOpen: 0.9, mouthLowerDown: 0.3, mouthUpperUp: 0.2 },
  viseme_E: { jawOpen: 0.55, mouthStretch: 0.4, mouthLowerDown: 0.2 },
  viseme_I: { jawOpen: 0.25, mouthStretch: 0.8, mouthSmile: 0.3, mouthLowerDown: 0.2 },
  viseme_O: { jawOpen: 0.6, mouthFunnel: 0.9 },
  viseme_U: { jawOpen: 0.3, mouthPucker: 1.0 },
};

function displacement(name, pos, lower, part) {
  if (name in VISEME_RECIPES) {
    const sum = [0, 0, 0];
    for (const [t, k] of Object.entries(VISEME_RECIPES[name])) {
      for (const side of ["jawOpen", "mouthClose", "mouthFunnel", "mouthPucker", "mouthRollUpper", "mouthRollLower"].includes(t) ? [0] : [1, -1]) {
        const d = arkitDisplacement(t, side, pos, lower, part);
        for (let i = 0; i < 3; i++) sum[i] += k * d[i];
      }
    }
    return sum;
  }
  const m = /^(.*?)(Left|Right)$/.exec(name);
  return m ? arkitDisplacement(m[1], m[2] === "Left" ? 1 : -1, pos, lower, part)
           : arkitDisplacement(name, 0, pos, lower, part);
}

// Give a geometry one relative morph target (positions and normals) per name.
function addMorphTargets(THREE, geometry, lowerOf, part) {
  const pos = geometry.attributes.position;
  geometry.computeVertexNormals();
  const restNormals = geometry.attributes.normal.array.slice();
  const names = [...OCULUS, ...ARKIT];
  const positions = [], normals = [];
  const work = geometry.clone();
  for (const name of names) {
    const d = new Float32Array(pos.count * 3);
    for (let i = 0; i < pos.count; i++) {
      const p = [pos.getX(i), pos.getY(i), pos.getZ(i)];
      const v = displacement(name, p, lowerOf(i, p), part);
      d[3 * i] = v[0]; d[3 * i + 1] = v[1]; d[3 * i + 2] = v[2];
    }
    const moved = work.attributes.position.array;
    for (let k = 0; k < moved.length; k++) moved[k] = pos.array[k] + d[k];
    work.attributes.position.needsUpdate = true;
    work.computeVertexNormals();
    const n = work.attributes.normal.array.map((v, k) => v - restNormals[k]);
    const dp = new THREE.Float32BufferAttribute(d, 3), dn = new THREE.Float32BufferAttribute(n, 3);
    dp.name = dn.name = name;   // Mesh.updateMorphTargets() names the targets after these
    positions.push(dp);
    normals.push(dn);
  }
  geometry.morphAttributes.position = positions;
  geometry.morphAttributes.normal = normals;
  geometry.morphTargetsRelative = true;
  work.dispose();
  return names;
}

function morphMesh(THREE, geometry, material, lowerOf, part) {
  const names = addMorphTargets(THREE, geometry, lowerOf, part);
  const mesh = new THREE.Mesh(geometry, material);
  mesh.updateMorphTargets();
  mesh.name = part;
  if (names.some((n) => !(n in mesh.morphTargetDictionary))) throw new Error("unnamed morph targets");
  return mesh;
}

// --- the head --------------------------------------------------------------------------------

function shapeHead(x, y, z) {
  // from the unit sphere: taller, narrower, a tapering jaw, a face pushed forward
  y *= 1.22; x *= 0.84; z *= 0.98;
  const below = smoothstep(0.1, -1.1, y);
  x *= 1 - 0.22 * below;
  if (z > 0) z *= 1 - 0.12 * below;
  if (z < 0) z *= 1.08 - 0.1 * below;
  const front = smoothstep(0.2, 0.8, z);
  z += front * 0.24 * gauss(x, 0.065) * smoothstep(0.15, -0.22, y) * smoothstep(-0.32, -0.2, y);  // nose
  z += front * 0.05 * gauss(x, 0.08) * gauss(y - 0.05, 0.12);                     // nose bridge
  z -= front * 0.06 * gauss(Math.abs(x) - 0.3, 0.12) * gauss(y - 0.1, 0.09);      // eye sockets
  z += front * 0.04 * gauss(Math.abs(x) - 0.3, 0.18) * gauss(y - 0.26, 0.05);     // brows
  z += front * 0.07 * gauss(x, 0.3) * gauss(y - MOUTH_Y, 0.22);                     // muzzle
  z += front * 0.05 * gauss(x, 0.18) * gauss(y + 0.95, 0.12);                       // chin
  return [x, y, z];
}

// z of the head's front surface at (x, y), by ray-casting the built head
function surfaceZ(THREE, head, x, y) {
  const ray = new THREE.Raycaster(new THREE.Vector3(x, y, 3), new THREE.Vector3(0, 0, -1));
  const hit = ray.intersectObject(head, false)[0];
  return hit ? hit.point.z : 0.9;
}

function buildHead(THREE) {
  const group = new THREE.Group();
  const skinMat = new THREE.MeshStandardMaterial({ color: 0xe0ac8a, roughness: 0.75 });

  const skull = new THREE.SphereGeometry(1, 128, 96);
  const p = skull.attributes.position;
  for (let i = 0; i < p.count; i++) {
    const [x, y, z] = shapeHead(p.getX(i), p.getY(i), p.getZ(i));
    p.setXYZ(i, x, y, z);
  }
  const rest = new THREE.Mesh(skull.clone(), skinMat);   // for ray casts before morphing
  rest.updateMatrixWorld();
  const zAt = (x, y) => surfaceZ(THREE, rest, x, y);
  const head = morphMesh(THREE, skull, skinMat,
    (_, [x, y, z]) => smoothstep(0.01, -0.08, y - MOUTH_Y) * (z > 0 ? 1 : 0), "skin");
  const parts = [head];

  // the mouth cavity: a dark lens between the lips, its lower half on the jaw
  const cav = [], cavIdx = [], cavLower = [];
  const N = 48;
  for (let i = 0; i <= N; i++) {
    const t = (i / N) * 2 * Math.PI;
    const x = MOUTH_HALF * 0.97 * Math.cos(t), y = MOUTH_Y + LIP_SEP * Math.sin(t);
    cav.push(x, y, zAt(x, y) + 0.006);
    cavLower.push(smoothstep(0, 0.5, -Math.sin(t)));
  }
  cav.push(0, MOUTH_Y, zAt(0, MOUTH_Y) + 0.006); cavLower.push(0.5);
  for (let i = 0; i < N; i++) cavIdx.push(N + 1, i, i + 1);
  const cavGeo = new THREE.BufferGeometry();
  cavGeo.setAttribute("position", new THREE.Float32BufferAttribute(cav, 3));
  cavGeo.setIndex(cavIdx);
  // Drawn after the skin without a depth test (a decal on the face), it marks the opening in
  // the stencil buffer; the teeth are drawn only there, then the lips over both.
  const cavMat = new THREE.MeshBasicMaterial({ color: 0x2a0d10, side: THREE.DoubleSide, depthTest: false,
    depthWrite: false, stencilWrite: true, stencilRef: 1, stencilZPass: THREE.ReplaceStencilOp });
  const cavity = morphMesh(THREE, cavGeo, cavMat, (i) => cavLower[i], "cavity");
  cavity.renderOrder = 1;
  parts.push(cavity);

  // teeth: two thin curved strips just inside the lips
  const teeth = (lower) => {
    const g = new THREE.BoxGeometry(0.3, 0.035, 0.02, 24, 2, 1);
    const a = g.attributes.position;
    const yc = MOUTH_Y + (lower ? -0.022 : 0.022);
    for (let i = 0; i < a.count; i++) {
      const x = a.getX(i), y = yc + a.getY(i);
      a.setXYZ(i, x, y, zAt(x * 1.05, MOUTH_Y) + 0.01 + a.getZ(i) * 0.5 - 0.004);
    }
    const mat = new THREE.MeshStandardMaterial({ color: 0xf4f1e8, roughness: 0.35, depthTest: false,
      depthWrite: false, stencilWrite: true, stencilRef: 1, stencilFunc: THREE.EqualStencilFunc });
    const mesh = morphMesh(THREE, g, mat, () => (lower ? 1 : 0), "teeth");
    mesh.renderOrder = 2;
    return mesh;
  };
  parts.push(teeth(false), teeth(true));

  // lips: a tube around the mouth's ellipse, thick mid-lip and thin at the corners
  const T = 96, R = 14;
  const lipPos = [], lipIdx = [], lipLower = [];
  for (let i = 0; i <= T; i++) {
    const t = (i / T) * 2 * Math.PI;
    const s = Math.sin(t), c = Math.cos(t);
    const cx = MOUTH_HALF * c, cy = MOUTH_Y + LIP_SEP * s;
    const cz = zAt(cx, cy) + 0.012;
    const r = (0.01 + 0.034 * Math.abs(s) ** 0.6) * (s > 0 ? 0.85 : 1);
    const nx = LIP_SEP * c, ny = MOUTH_HALF * s, nl = Math.hypot(nx, ny);   // outward in-plane
    for (let j = 0; j <= R; j++) {
      const ph = (j / R) * 2 * Math.PI;
      lipPos.push(cx + r * Math.cos(ph) * nx / nl, cy + r * Math.cos(ph) * ny / nl * 0.8, cz + r * Math.sin(ph) * 0.7);
      lipLower.push(smoothstep(0, 0.5, -s));
    }
  }
  for (let i = 0; i < T; i++) {
    for (let j = 0; j < R; j++) {
      const a = i * (R + 1) + j, b = a + R + 1;
      lipIdx.push(a, b, a + 1, b, b + 1, a + 1);
    }
  }
  const lipGeo = new THREE.BufferGeometry();
  lipGeo.setAttribute("position", new THREE.Float32BufferAttribute(lipPos, 3));
  lipGeo.setIndex(lipIdx);
  const lips = morphMesh(THREE, lipGeo, new THREE.MeshStandardMaterial({ color: 0xb5545a, roughness: 0.5 }),
    (i) => lipLower[i], "lip");
  lips.renderOrder = 3;
  parts.push(lips);

  // eyes, brows, ears, hair, neck: no morph targets
  const white = new THREE.MeshStandardMaterial({ color: 0xf8f8f4, roughness: 0.3 });
  const iris = new THREE.MeshStandardMaterial({ color: 0x3d6e8f, roughness: 0.3 });
  const pupil = new THREE.MeshBasicMaterial({ color: 0x080808 });
  const dark = new THREE.MeshStandardMaterial({ color: 0x3a2618, roughness: 0.9 });
  for (const sx of [-1, 1]) {
    const ex = 0.3 * sx, ey = 0.1, ez = zAt(ex, ey) - 0.055;
    const eye = new THREE.Mesh(new THREE.SphereGeometry(0.12, 32, 24), white);
    eye.position.set(ex, ey, ez);
    const ir = new THREE.Mesh(new THREE.SphereGeometry(0.055, 24, 16), iris);
    ir.position.set(ex, ey, ez + 0.104); ir.scale.set(1, 1, 0.35);
    const pu = new THREE.Mesh(new THREE.SphereGeometry(0.027, 16, 12), pupil);
    pu.position.set(ex, ey, ez + 0.117); pu.scale.set(1, 1, 0.4);
    // the upper lid: a cap over the eyeball's top half, tipped back when open
    const lid = new THREE.Mesh(new THREE.SphereGeometry(0.128, 32, 16, 0, Math.PI * 2, 0, Math.PI / 2), skinMat);
    lid.position.set(ex, ey, ez); lid.rotation.x = LID_OPEN; lid.name = "lid";
    const brow = new THREE.Mesh(new THREE.CapsuleGeometry(0.022, 0.18, 4, 12), dark);
    brow.position.set(ex + 0.01 * sx, 0.29, zAt(ex, 0.29) + 0.015);
    brow.rotation.z = Math.PI / 2 - 0.12 * sx;
    const ear = new THREE.Mesh(new THREE.SphereGeometry(0.16, 24, 16), skinMat);
    ear.position.set(0.82 * sx, -0.05, -0.05); ear.scale.set(0.35, 1.05, 0.65);
    group.add(eye, ir, pu, lid, brow, ear);
  }
  const hair = new THREE.Mesh(new THREE.SphereGeometry(1.05, 64, 32, 0, Math.PI * 2, 0, Math.PI * 0.5), dark);
  hair.scale.set(0.87, 1.2, 1.04); hair.rotation.x = -0.45; hair.position.set(0, 0.13, -0.08);
  const neck = new THREE.Mesh(new THREE.CylinderGeometry(0.36, 0.42, 1.0, 48), skinMat);
  neck.position.set(0, -1.35, -0.15);
  const shoulders = new THREE.Mesh(new THREE.SphereGeometry(1, 48, 24), new THREE.MeshStandardMaterial({ color: 0x33506e, roughness: 0.9 }));
  shoulders.scale.set(1.6, 0.45, 0.8); shoulders.position.set(0, -2.05, -0.2);
  group.add(hair, neck, shoulders, ...parts);
  return { group, morphed: parts };
}

// --- the page ---------------------------------------------------------------------------------

async function main() {
  const adaptor = await MorphAdaptor.load(client, { names: "both" });
  // For tests and curious users: the weights of every frame of the utterance (`trace`), of
  // the latest frame (`weights`, both sets) and those drawn (`drawn`); `pose` ({name:
  // weight}) shows a fixed pose instead of the speech; `hold` keeps the drawn pose and the
  // list on screen (for a screenshot) while the weights go on.
  const debug = window.avatarDebug = { webgl: false, frames: 0, weights: {}, trace: [], adaptor,
                                       pose: null, hold: false };
  client.addEventListener("utterance-start", () => { debug.trace = []; });

  let THREE = null, renderer = null, scene, camera, head;
  if (!webglAvailable()) {
    showError("WebGL is not available in this browser, so the 3-D head cannot be drawn. " +
              "The morph weights are still computed (listed on the right).");
  } else {
    try {
      THREE = await import("/client/vendor/three.module.js");
    } catch (err) {
      showError("three.js is missing from /client/vendor/: run `make setup` on the server.");
    }
  }
  if (THREE) {
    try {
      renderer = new THREE.WebGLRenderer({ antialias: true, stencil: true });   // the teeth need it
    } catch (err) {
      renderer = null;
      showError(`WebGL could not start (${err.message}), so the 3-D head cannot be drawn.`);
    }
  }
  if (renderer) {
    renderer.setPixelRatio(window.devicePixelRatio);
    $("stage").prepend(renderer.domElement);
    scene = new THREE.Scene();
    scene.background = new THREE.Color(0x20252b);
    camera = new THREE.PerspectiveCamera(30, 1, 0.1, 50);
    camera.position.set(1.0, 0.0, 7.0);
    camera.lookAt(0, -0.3, 0);
    scene.add(new THREE.HemisphereLight(0xfff4e8, 0x40362e, 1.6));
    const key = new THREE.DirectionalLight(0xffffff, 2.2);
    key.position.set(2, 2.5, 4);
    const rim = new THREE.DirectionalLight(0x9fb8ff, 0.8);
    rim.position.set(-3, 1, -2);
    scene.add(key, rim);
    head = buildHead(THREE);
    head.group.rotation.y = 0.18;
    scene.add(head.group);
    debug.webgl = true;
    debug.meshes = head.morphed;
  }

  let blinkUntil = 0, nextBlink = performance.now() + 2500;
  client.animate(({ sample }) => {
    const all = adaptor.weightsAt(sample);
    debug.weights = all;
    if (sample !== null) debug.trace.push({ sample, ...all });
    if (debug.hold && renderer) {   // eyes open, mouth as last drawn
      head.group.traverse((o) => { if (o.name === "lid") o.rotation.x = LID_OPEN; });
      renderer.render(scene, camera);
      return;
    }
    // the chosen set only: the other set's targets stay at 0 (they would add a second mouth)
    const names = $("names").value === "oculus" ? OCULUS : ARKIT;
    const shown = debug.pose || Object.fromEntries(names.map((n) => [n, all[n]]));
    const top = Object.entries(shown).filter(([, v]) => v > 0.05).sort((a, b) => b[1] - a[1]).slice(0, 6);
    $("weights").textContent = top.map(([n, v]) => `${n.padEnd(20)} ${v.toFixed(2)}`).join("\n");
    if (!renderer) return;
    debug.drawn = shown;
    for (const mesh of head.morphed) mesh.morphTargetInfluences.fill(0);
    adaptor.apply(head.group, sample, shown);
    const now = performance.now();
    if (now > nextBlink) { blinkUntil = now + 130; nextBlink = now + 2500 + Math.random() * 4000; }
    head.group.traverse((o) => { if (o.name === "lid") o.rotation.x = now < blinkUntil ? LID_SHUT : LID_OPEN; });
    const stage = $("stage"), w = stage.clientWidth, h = stage.clientHeight;
    if (renderer.domElement.width !== Math.floor(w * renderer.getPixelRatio())) {
      renderer.setSize(w, h, false);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
    }
    renderer.render(scene, camera);
    debug.frames++;
  });
}

main().catch((err) => { showError(`The avatar could not start: ${err.message}`); throw err; });
