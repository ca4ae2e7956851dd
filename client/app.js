// The demo page at "/": text box, controls, face and captions.
import { LipclockClient } from "/client/lipclock.js";
import { createFace } from "/client/face.js";
import { createTimeline } from "/client/timeline.js";

const $ = (id) => document.getElementById(id);
const client = new LipclockClient({ channel: new URLSearchParams(location.search).get("channel") || "default" });
window.lipclockClient = client;

// ---- the face and its animation loop: one place that draws every frame ----------------
let face = null;
const last = { lipGap: 0, ms: 0 };       // what the last frame drew
window.lipclockDebug = {
  get audioSample() { return client.debug.audioSample; },
  get mouthSample() { return client.debug.mouthSample; },
  get lipGap() { return last.lipGap; },  // measured on the drawn mesh, not the stream
  get drawMs() { return last.ms; },
  get look() { return face ? face.look : null; },
  get backend() { return face ? face.backend : null; },
};

async function startFace() {
  face = await createFace($("face"), { look: $("look").value });
  window.lipclockFace = face;
  const expression = () => face.setExpression({ smile: $("smile").value / 100, brow: $("brow").value / 100,
                                                frown: $("frown").value / 100 });
  for (const id of ["smile", "brow", "frown"]) $(id).oninput = expression;
  expression();
  $("look").onchange = () => face.setLook($("look").value);
  const strip = createTimeline($("timeline"));
  client.animate(({ sample, mouth, time }) => {
    const drawn = face.draw(mouth, time);
    last.lipGap = drawn.lipGap; last.ms = drawn.ms;
    strip.draw(client.utt, sample);
    return drawn;   // the client's debug object and "frame" event report what was drawn
  });
}
startFace().catch((err) => { $("status").textContent = `face failed: ${err.message}`; console.error(err); });

// ---- voices, connection status, captions ---------------------------------------------
let springDefaults = {};   // the server's spring constants, from GET /voices
fetch("/voices").then((r) => r.json()).then((v) => {
  for (const voice of v.voices) $("voice").add(new Option(voice.name, voice.name, voice.name === v.default, voice.name === v.default));
  for (const m of v.mouth_models) $("model").add(new Option(m, m, m === "spring", m === "spring"));
  springDefaults = v.spring_params || {};
  showSprings();
});

// ---- spring-model sliders: log-scale factors on every stiffness and damping constant ---
const factor = (id) => 2 ** Number($(id).value);
function showSprings() {
  $("springs").disabled = $("model").value !== "spring";
  $("stiffnessOut").value = "×" + factor("stiffness").toFixed(2);
  $("dampingOut").value = "×" + factor("damping").toFixed(2);
}
for (const id of ["model", "stiffness", "damping"]) $(id).addEventListener("input", showSprings);
$("model").addEventListener("change", showSprings);
// The spring_params to send: only when the spring model is chosen and a slider moved.
// The skull is the head's anchor, not a mouth muscle, so it keeps its constants.
export function springParams() {
  if ($("model").value !== "spring") return undefined;
  const k = factor("stiffness"), c = factor("damping");
  if (k === 1 && c === 1) return undefined;
  const out = {};
  for (const [key, value] of Object.entries(springDefaults)) {
    if (key.startsWith("skull.")) continue;
    if (key.endsWith(".stiffness")) out[key] = value * k;
    else if (key.endsWith(".damping")) out[key] = value * c;
  }
  return out;
}

client.addEventListener("open", () => { $("status").textContent = "connected"; });
client.addEventListener("hello", () => {   // device mode: the server plays the sound
  if (client.deviceMode) { $("unlock").hidden = true; $("status").textContent = "connected (device clock)"; }
});
client.addEventListener("close", () => { $("status").textContent = "reconnecting…"; });
client.addEventListener("server-error", (e) => { $("status").textContent = e.detail.reason; });
client.addEventListener("utterance-start", () => { $("caption").textContent = ""; });
client.addEventListener("word", (e) => { $("caption").textContent += (e.detail.orth || e.detail.text) + " "; });

// ---- audio unlock and the speak/stop buttons -------------------------------------------
async function ensureAudio() {
  if (client.deviceMode) return true;
  const ok = await client.unlock();
  $("unlock").hidden = ok;
  return ok;
}
client.unlock().then((ok) => { $("unlock").hidden = ok || client.deviceMode; });
$("unlock").onclick = ensureAudio;
$("speak").onclick = async () => {
  await ensureAudio();
  const opts = { voice: $("voice").value || undefined, rate_wpm: Number($("rate").value),
                 mouth_model: $("model").value || undefined };
  if (Number($("pitch").value) > 0) opts.pitch_hz = Number($("pitch").value);
  const springs = springParams();
  if (springs) opts.spring_params = springs;
  client.speak($("text").value, opts);
};
$("stop").onclick = () => client.stop();
