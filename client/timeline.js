// A live timeline strip: phones, visemes and the mouth opening of the current utterance
// against the audio clock, with the playhead at the sample being heard. Canvas 2-D.
//
//   const strip = createTimeline(canvas, { windowS: 2.5 });
//   client.animate(({ sample }) => { ...; strip.draw(client.utt, sample); });
//
// The utterance object is the client's own (lipclock.js): its start message (phones,
// visemes, sample_rate) and the lip gaps streamed so far (one per mouth frame).

const COLORS = { phone: "#9fb3c8", viseme: "#f2c66d", gap: "#ff6b6b", head: "#ffffff",
                 grid: "#3b4450", text: "#e8e8e8", bg: "#1b2026" };
const GAP_MAX_MM = 20;  // full scale of the mouth-opening trace

export function createTimeline(canvas, { windowS = 2.5, leadFraction = 0.35 } = {}) {
  const ctx = canvas.getContext("2d");
  let last = { sample: null, id: null };

  function draw(utt, sample) {
    const w = (canvas.width = canvas.clientWidth * devicePixelRatio);
    const h = (canvas.height = canvas.clientHeight * devicePixelRatio);
    ctx.fillStyle = COLORS.bg;
    ctx.fillRect(0, 0, w, h);
    if (!utt || !utt.start) return;
    // hold the last position after the utterance ends so the strip can still be read
    if (sample === null || sample === undefined) {
      sample = last.id === utt.id ? last.sample : null;
      if (sample === null) return;
    }
    last = { sample, id: utt.id };
    const sr = utt.sr;
    const span = windowS * sr;
    const from = sample - span * leadFraction;
    const x = (s) => ((s - from) / span) * w;
    const rowH = h / 4;
    ctx.font = `${Math.round(rowH * 0.45)}px system-ui, sans-serif`;
    ctx.textBaseline = "middle";
    ctx.textAlign = "center";
    const row = (items, key, y, color) => {
      for (const it of items) {
        if (it.end < from || it.start > from + span) continue;
        const x0 = x(it.start), x1 = x(it.end);
        ctx.strokeStyle = COLORS.grid;
        ctx.strokeRect(x0, y + 2, x1 - x0, rowH - 4);
        const label = String(it[key]).replace(/\d$/, "");
        if (ctx.measureText(label).width + 4 < x1 - x0) {   // a label only where it fits
          ctx.fillStyle = it.start <= sample && sample < it.end ? color : COLORS.text;
          ctx.fillText(label, (x0 + x1) / 2, y + rowH / 2);
        }
      }
    };
    row(utt.start.phones, "phone", 0, COLORS.phone);
    row(utt.start.visemes, "viseme", rowH, COLORS.viseme);
    // mouth opening (lip gap, mm) on the bottom half
    const top = 2 * rowH, bottom = h - 2;
    ctx.strokeStyle = COLORS.grid;
    ctx.beginPath(); ctx.moveTo(0, bottom); ctx.lineTo(w, bottom); ctx.stroke();
    ctx.strokeStyle = COLORS.gap;
    ctx.lineWidth = 2 * devicePixelRatio;
    ctx.beginPath();
    const perFrame = sr / utt.rateHz;
    const k0 = Math.max(0, Math.floor(from / perFrame)), k1 = Math.ceil((from + span) / perFrame);
    let pen = false;
    for (let k = k0; k <= k1; k++) {
      const g = utt.gap[k];
      if (g === undefined) { pen = false; continue; }   // not streamed yet
      const y = bottom - Math.min(g / GAP_MAX_MM, 1) * (bottom - top);
      if (pen) ctx.lineTo(x(k * perFrame), y); else ctx.moveTo(x(k * perFrame), y);
      pen = true;
    }
    ctx.stroke();
    ctx.lineWidth = 1;
    // the playhead: the sample being heard now
    ctx.strokeStyle = COLORS.head;
    ctx.beginPath(); ctx.moveTo(x(sample), 0); ctx.lineTo(x(sample), h); ctx.stroke();
  }

  return { draw };
}
