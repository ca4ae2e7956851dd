// lipclock client library (ES module, no build step).
// Connects to a channel, plays streamed audio on an AudioContext, and tells a renderer,
// on every animation frame, which audio-clock sample is being heard and the mouth state
// at that sample. Protocol: docs/protocol.md (version 1).

export const PROTOCOL_VERSION = 1;
const HEADER_BYTES = 16;

// What each server message must carry before the client acts on it (docs/protocol.md):
// a missing or mistyped field is one warning, never a half-built utterance.
const isInt = (v) => Number.isInteger(v) && v >= 0;
const isPos = (v) => typeof v === "number" && v > 0 && Number.isFinite(v);
const isNum = (v) => typeof v === "number" && Number.isFinite(v);
const isArr = Array.isArray;
const REQUIRED = {
  hello: { protocol_version: isInt, sample_rate: isPos },
  clock: { device_sample: isNum, server_time_s: isNum },
  start: { utterance_id: isInt, sample_rate: isPos, num_samples: isInt, mouth_rate_hz: isPos,
           words: isArr, phones: isArr, visemes: isArr, mouth_nodes: isArr },
  mouth: { utterance_id: isInt, first_frame: isInt, frames: isArr, lip_gap: isArr },
  end: { utterance_id: isInt, end_sample: isInt },
  pong: { t_client: isNum, server_time_s: isNum },
};

function malformed(m) {
  if (m === null || typeof m !== "object" || Array.isArray(m)) return "not a JSON object";
  if (typeof m.type !== "string") return "no message type";
  const need = REQUIRED[m.type] || {};
  for (const [field, ok] of Object.entries(need)) {
    if (!ok(m[field])) return `${m.type}.${field} is missing or of the wrong type`;
  }
  if (m.type === "mouth" && m.frames.length !== m.lip_gap.length) return "mouth frames and lip_gap differ in length";
  return null;
}

export class LipclockClient extends EventTarget {
  constructor({ url, channel = "default", key = null, jitterBufferS = 0.12 } = {}) {
    super();
    const base = url || `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/ws`;
    const q = new URLSearchParams({ channel });
    if (key) q.set("key", key);
    this.url = `${base}?${q}`;
    this.jitterBufferS = jitterBufferS;
    this.ctx = null;
    this.utt = null;          // the utterance being played
    this.backoffMs = 250;
    this.closed = false;
    this.debug = Object.freeze({ audioSample: 0, mouthSample: 0, lipGap: 0 });
    // audio chunks received, chunks that arrived after their play time (an underrun: the
    // late part is skipped so the clock stays exact), and per chunk how early it arrived
    this.stats = { chunks: 0, lateChunks: 0, slackMs: [] };
    this._connect();
  }

  // Browsers only let audio start after a user gesture: call this from a click handler.
  async unlock() {
    if (!this.ctx) this.ctx = new AudioContext({ latencyHint: "interactive" });
    if (this.ctx.state !== "running") {
      // Without a user gesture, resume() can stay pending forever: don't wait on it, so
      // the page can show its "tap to enable sound" prompt instead of failing silently.
      await Promise.race([this.ctx.resume(), new Promise((r) => setTimeout(r, 300))]);
    }
    this.dispatchEvent(new Event(this.ctx.state === "running" ? "audio-ready" : "audio-blocked"));
    return this.ctx.state === "running";
  }

  send(msg) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(msg));
  }
  speak(text, opts = {}) { this.send({ type: "speak", text, ...opts }); }
  stop() { this.send({ type: "stop" }); }

  close() { this.closed = true; clearInterval(this.pingTimer); if (this.ws) this.ws.close(); }

  _connect() {
    const ws = new WebSocket(this.url);
    ws.binaryType = "arraybuffer";
    this.ws = ws;
    ws.onopen = () => { this.backoffMs = 250; this.dispatchEvent(new Event("open")); };
    ws.onmessage = (ev) => {
      try {
        if (ev.data instanceof ArrayBuffer) this._onAudio(ev.data);
        else this._onJson(JSON.parse(ev.data));
      } catch (err) {
        console.warn("lipclock: ignoring a malformed message:", err.message);
      }
    };
    ws.onclose = () => {
      this._silence("disconnected");
      this.dispatchEvent(new Event("close"));
      if (!this.closed) {           // reconnect with exponential backoff
        setTimeout(() => this._connect(), this.backoffMs);
        this.backoffMs = Math.min(this.backoffMs * 2, 8000);
      }
    };
  }

  _onJson(m) {
    const bad = malformed(m);
    if (bad) { console.warn(`lipclock: ignoring a malformed message: ${bad}`); return; }
    switch (m.type) {
      case "hello":
        if (m.protocol_version !== PROTOCOL_VERSION) {
          console.warn(`lipclock: server speaks protocol ${m.protocol_version}, ` +
                       `this client ${PROTOCOL_VERSION}; ignoring its messages`);
          this.incompatible = true;
        }
        this.sampleRate = m.sample_rate;
        this.deviceMode = m.clock === "device";
        if (this.deviceMode) this._startPinging();
        this.dispatchEvent(new CustomEvent("hello", { detail: m }));
        break;
      case "clock":
        this.devClock = { sample: m.device_sample, serverTime: m.server_time_s };
        break;
      case "start":
        if (this.incompatible) return;
        this._silence("replaced");
        this.utt = { id: m.utterance_id, sr: m.sample_rate, n: m.num_samples, start: m,
                     deviceStart: m.device_start ?? null,
                     t0: null, sources: [], frames: [], gap: [], width: [], jaw: [],
                     rateHz: m.mouth_rate_hz,
                     wordIdx: 0, ended: false, endSample: m.num_samples };
        this.dispatchEvent(new CustomEvent("utterance-start", { detail: m }));
        break;
      case "mouth": {
        const u = this.utt;
        if (!u || u.id !== m.utterance_id) return;
        m.frames.forEach((f, i) => {
          const k = m.first_frame + i;
          u.frames[k] = f; u.gap[k] = m.lip_gap[i]; u.width[k] = m.width[i]; u.jaw[k] = m.jaw[i];
        });
        break;
      }
      case "end": {
        const u = this.utt;
        if (!u || u.id !== m.utterance_id) return;
        u.ended = true;
        u.endSample = m.end_sample;
        if (m.stopped) {
          this._silence("stopped");
          this.dispatchEvent(new CustomEvent("stop", { detail: m }));
        }
        break;
      }
      case "error":
        console.warn(`lipclock: server error ${m.code}: ${m.reason}`);
        this.dispatchEvent(new CustomEvent("server-error", { detail: m }));
        break;
      case "pong": {
        // NTP-style: offset of the server clock from ours, from the lowest-RTT exchanges
        const now = performance.now() / 1000;
        const rtt = now - m.t_client;
        this.pings = (this.pings || []).concat([[rtt, m.server_time_s - (m.t_client + now) / 2]]).slice(-40);
        const best = [...this.pings].sort((a, b) => a[0] - b[0]).slice(0, Math.max(3, Math.floor(this.pings.length / 4)));
        const offs = best.map((p) => p[1]).sort((a, b) => a - b);
        this.serverOffset = offs[Math.floor(offs.length / 2)];
        break;
      }
      default:
        console.warn("lipclock: unknown message type", m.type);
    }
  }

  _startPinging() {
    clearInterval(this.pingTimer);
    let n = 0;
    const ping = () => { this.send({ type: "ping", t_client: performance.now() / 1000 }); n++; };
    for (let i = 0; i < 5; i++) setTimeout(ping, i * 60);   // a quick burst, then 1 Hz
    this.pingTimer = setInterval(ping, 1000);
  }

  _onAudio(buf) {
    const u = this.utt;
    const dv = new DataView(buf);
    const magic = buf.byteLength < HEADER_BYTES ? "" :
      String.fromCharCode(dv.getUint8(0), dv.getUint8(1), dv.getUint8(2), dv.getUint8(3));
    if (magic !== "LCA1" || (buf.byteLength - HEADER_BYTES) % 2) {
      console.warn(`lipclock: ignoring a malformed message: bad audio frame (${buf.byteLength} bytes)`);
      return;
    }
    if (this.deviceMode) return;    // the server's device plays it
    if (!u || !this.ctx) return;
    const id = dv.getUint32(4, true);
    const first = Number(dv.getBigUint64(8, true));
    if (id !== u.id) return;
    const pcm = new Int16Array(buf, HEADER_BYTES);
    const audio = this.ctx.createBuffer(1, pcm.length, u.sr);  // the browser resamples
    const ch = audio.getChannelData(0);
    for (let i = 0; i < pcm.length; i++) ch[i] = pcm[i] / 32768;
    if (u.t0 === null) u.t0 = this.ctx.currentTime + this.jitterBufferS;
    const src = this.ctx.createBufferSource();
    src.buffer = audio;
    src.connect(this.tap || this.ctx.destination);
    const when = u.t0 + first / u.sr;
    this.stats.chunks++;
    this.stats.slackMs.push(Math.round((when - this.ctx.currentTime) * 1000));
    if (this.stats.slackMs.length > 2000) this.stats.slackMs.shift();
    if (when < this.ctx.currentTime) {
      this.stats.lateChunks++;
      // late chunk: play the part still in the future so the clock stays exact
      const late = this.ctx.currentTime - when;
      if (late < audio.duration) src.start(this.ctx.currentTime, late);
    } else {
      src.start(when);
    }
    u.sources.push(src);
  }

  _silence(why) {
    const u = this.utt;
    if (!u) return;
    for (const s of u.sources) { try { s.stop(); } catch (_) { /* not started */ } }
    u.sources = [];
    u.silenced = why;
  }

  // The AudioContext time of the sound leaving the speakers at performance time perfMs.
  // getOutputTimestamp() pairs the two clocks, output latency included; where it is
  // missing (older Safari) currentTime minus outputLatency is the best estimate.
  outputTime(perfMs = performance.now()) {
    const ctx = this.ctx;
    const ts = ctx.getOutputTimestamp ? ctx.getOutputTimestamp() : null;
    if (ts && ts.performanceTime > 0) return ts.contextTime + (perfMs - ts.performanceTime) / 1000;
    const latency = ctx.outputLatency || ctx.baseLatency || 0;
    return ctx.currentTime - latency + (perfMs - performance.now()) / 1000;
  }

  // The audio-clock sample being heard at performance time perfMs (default: now), or null.
  currentSample(perfMs = performance.now()) {
    const u = this.utt;
    if (this.deviceMode) {
      // the device's sample then, from its last clock message and our offset to the server
      if (!u || u.silenced || u.deviceStart === null || !this.devClock || this.serverOffset === undefined) return null;
      const serverNow = perfMs / 1000 + this.serverOffset;
      const s = Math.floor(this.devClock.sample + (serverNow - this.devClock.serverTime) * u.sr) - u.deviceStart;
      return s >= 0 && s < u.endSample ? s : null;
    }
    if (!u || u.t0 === null || !this.ctx || u.silenced) return null;
    const s = Math.floor((this.outputTime(perfMs) - u.t0) * u.sr);
    if (s < 0 || s >= u.endSample) return null;
    return s;
  }

  // Mouth state at a sample: interpolated node positions and measures (lip gap, width, jaw; mm).
  mouthAt(sample) {
    const u = this.utt;
    if (!u || sample === null) return null;
    const pos = sample * u.rateHz / u.sr;
    const k = Math.floor(pos);
    const a = u.frames[k], b = u.frames[k + 1] || a;
    if (!a) return null;
    const f = pos - k;
    const nodes = a.map((p, i) => [p[0] + (b[i][0] - p[0]) * f, p[1] + (b[i][1] - p[1]) * f]);
    const lerp = (v) => (v[k] ?? 0) + ((v[k + 1] ?? v[k] ?? 0) - (v[k] ?? 0)) * f;
    return { nodes, names: u.start.mouth_nodes, lipGap: lerp(u.gap), width: lerp(u.width),
             jaw: lerp(u.jaw), sample: Math.round(k * u.sr / u.rateHz + f * u.sr / u.rateHz) };
  }

  // Call render({sample, mouth, time}) on every animation frame, for the sample heard at
  // the frame's time. render may return what it drew ({sample, lipGap, ms}, as face.js's
  // draw() does); the "frame" event and the debug object then report the drawn values.
  animate(render) {
    const tick = (time) => {
      const sample = this.currentSample(time);
      const mouth = this.mouthAt(sample);
      const u = this.utt;
      if (u && sample !== null) {
        const words = u.start.words;
        while (u.wordIdx < words.length && words[u.wordIdx].start <= sample) {
          this.dispatchEvent(new CustomEvent("word", { detail: words[u.wordIdx] }));
          u.wordIdx++;
        }
      }
      const finished = this.deviceMode
        ? (u && u.ended && sample === null && u.deviceStart !== null && this.devClock &&
           this.devClock.sample >= u.deviceStart + u.endSample)
        : (u && u.ended && sample === null && u.t0 !== null &&
           this.ctx && this.ctx.currentTime > u.t0 + u.endSample / u.sr);
      if (finished && !u.doneFired) {
        u.doneFired = true;
        this.dispatchEvent(new CustomEvent("utterance-end", { detail: { id: u.id } }));
      }
      const drawn = render({ sample, mouth, time }) || {};
      this.debug = Object.freeze({
        audioSample: sample ?? 0,
        mouthSample: drawn.sample ?? (mouth ? mouth.sample : 0) ?? 0,
        lipGap: drawn.lipGap ?? (mouth ? mouth.lipGap : 0),
        drawMs: drawn.ms ?? null,
        frameTime: time });
      this.dispatchEvent(new CustomEvent("frame", { detail: {
        time, utterance: u ? u.id : null, audioSample: sample, ...this.debug,
        outputTime: this.ctx && !this.deviceMode ? this.outputTime(time) : null } }));
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }
}
