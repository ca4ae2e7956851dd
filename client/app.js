// The demo page at "/": text box, controls, face and captions.
import { LipclockClient } from "/client/lipclock.js";
import { drawFace } from "/client/face.js";

const $ = (id) => document.getElementById(id);
const client = new LipclockClient({ channel: new URLSearchParams(location.search).get("channel") || "default" });
window.lipclockDebug = { get audioSample() { return client.debug.audioSample; },
  get mouthSample() { return client.debug.mouthSample; }, get lipGap() { return client.debug.lipGap; } };
window.lipclockClient = client;

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

const canvas = $("face"), ctx = canvas.getContext("2d");
let blinkUntil = 0, nextBlink = performance.now() + 2000;
client.animate(({ mouth }) => {
  const now = performance.now();
  if (now > nextBlink) { blinkUntil = now + 120; nextBlink = now + 2000 + Math.random() * 4000; }
  canvas.width = canvas.clientWidth; canvas.height = canvas.clientHeight;
  drawFace(ctx, canvas.width, canvas.height, mouth, { blink: now < blinkUntil, wireframe: $("wire").checked });
});
