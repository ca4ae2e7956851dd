// The demo page at "/": text box, controls, face and captions.
import { LipclockClient } from "/client/lipclock.js";
import { createFace } from "/client/face.js";

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
  client.animate(({ mouth }) => {
    const drawn = face.draw(mouth, performance.now());
    last.lipGap = drawn.lipGap; last.ms = drawn.ms;
  });
}
startFace().catch((err) => { $("status").textContent = `face failed: ${err.message}`; console.error(err); });

// ---- voices, connection status, captions ---------------------------------------------
fetch("/voices").then((r) => r.json()).then((v) => {
  for (const voice of v.voices) $("voice").add(new Option(voice.name, voice.name, voice.name === v.default, voice.name === v.default));
  for (const m of v.mouth_models) $("model").add(new Option(m, m, m === "spring", m === "spring"));
});

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
  client.speak($("text").value, opts);
};
$("stop").onclick = () => client.stop();
