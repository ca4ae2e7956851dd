// Morph-target weights for 3-D avatars, from a LipclockClient's stream (ES module, no
// dependency on three.js). Two sets of names, both 0..1:
//  * the 15 Oculus visemes (Ready Player Me spelling: viseme_I/O/U for Oculus ih/oh/ou),
//    from the utterance's phones and visemes (`start` message) through the table
//    viseme_tables/morphs.tsv (served at /tables/morphs.tsv), cross-faded on the sample clock;
//  * ARKit mouth/jaw blendshapes, from the continuous mouth measures (`mouth` messages:
//    lip gap, width, jaw drop in mm), normalised by the ranges in RANGES.
// docs/client-3d.md has the API and how to hook a glTF avatar.

export const OCULUS = ["viseme_sil", "viseme_PP", "viseme_FF", "viseme_TH", "viseme_DD",
  "viseme_kk", "viseme_CH", "viseme_SS", "viseme_nn", "viseme_RR", "viseme_aa", "viseme_E",
  "viseme_I", "viseme_O", "viseme_U"];

export const ARKIT = ["jawOpen", "mouthClose", "mouthFunnel", "mouthPucker",
  "mouthSmileLeft", "mouthSmileRight", "mouthStretchLeft", "mouthStretchRight",
  "mouthRollUpper", "mouthRollLower", "mouthPressLeft", "mouthPressRight",
  "mouthLowerDownLeft", "mouthLowerDownRight", "mouthUpperUpLeft", "mouthUpperUpRight"];

// Other spellings avatars use for the same targets; apply() tries them when the mesh lacks
// the first name (Oculus SDK: viseme_ih/oh/ou; some exporters drop the prefix).
export const ALIASES = {
  viseme_I: ["viseme_ih", "ih"], viseme_O: ["viseme_oh", "oh"], viseme_U: ["viseme_ou", "ou"],
};

// Ranges of the mouth measures (mm), read off viseme_tables/visemes.tsv: a weight is 0 at
// the first number and 1 at the second, linear and clamped in between.
export const RANGES = {
  jawOpen: [2, 15],        // jaw drop: rest 2 mm .. "open" viseme 15 mm
  mouthClose: [3, 0],      // lip gap: lips count as closing under 3 mm, shut at 0
  mouthPress: [1, 0],      // lip gap: pressed together (p b m reach 0; f v keep 1 mm)
  narrow: [50, 36],        // width: rest 50 mm .. "rounded" 36 mm (split pucker/funnel)
  rounding: [0, 8],        // lip gap of a narrowed mouth: 0 = pucker, 8 mm+ = funnel
  mouthStretch: [50, 60],  // width: rest 50 mm .. "spread" 60 mm
  mouthSmile: [54, 62],    // width: only past the vowels' 54 mm do the corners lift
  lipsApart: [0, 6],       // lip gap beyond what the jaw drop opens (gap - (jaw - 2)):
                           //   the lips themselves part (mouthLowerDown / mouthUpperUp)
};

// Targets no measure shows, from the viseme weights: f v tuck the lower lip under the teeth;
// p b m press the lips a little inwards. {target: {viseme: factor}}
export const ROLLS = {
  mouthRollLower: { viseme_FF: 1.0, viseme_PP: 0.3 },
  mouthRollUpper: { viseme_PP: 0.3 },
};

// Half of a viseme cross-fade (seconds); shorter for visemes shorter than two of these.
export const CROSSFADE_HALF_S = 0.03;

const clamp01 = (x) => Math.min(1, Math.max(0, x));
const ramp = (v, [a, b]) => clamp01((v - a) / (b - a));
const smooth = (t) => t * t * (3 - 2 * t);

// morphs.tsv text -> {viseme class or phone: Oculus morph name}. `source` names the file in
// errors, which read "source:line: what is wrong". The server checks the keys against its
// viseme classes and phones (lipclock/face/morphs.py); here only the shape and the morph
// names can be checked.
export function parseMorphTable(text, source = "morphs.tsv") {
  const table = {};
  text.split(/\r?\n/).forEach((raw, i) => {
    const line = raw.split("#")[0].trim();
    if (!line) return;
    const where = `${source}:${i + 1}`;
    const fields = line.split("\t").map((f) => f.trim());
    if (fields.length !== 2 || !fields[0] || !fields[1]) {
      throw new Error(`${where}: expected 2 tab-separated columns (key, morph), got ${JSON.stringify(line)}`);
    }
    const [key, morph] = fields;
    if (!OCULUS.includes(morph)) {
      throw new Error(`${where}: unknown morph target ${JSON.stringify(morph)}; expected one of ${OCULUS.join(" ")}`);
    }
    if (key in table) throw new Error(`${where}: ${JSON.stringify(key)} is given twice`);
    table[key] = morph;
  });
  if (!Object.keys(table).length) throw new Error(`${source}: no rows`);
  return table;
}

export class MorphAdaptor {
  // client: a LipclockClient (or anything with .utt, .currentSample() and .mouthAt(sample)).
  // table: {viseme class or phone: Oculus morph} (parseMorphTable); MorphAdaptor.load()
  // fetches it from the server. names: "oculus" | "arkit" | "both".
  constructor(client, { table, names = "both" } = {}) {
    if (!table) throw new Error("MorphAdaptor needs the viseme table: use MorphAdaptor.load()");
    if (!["oculus", "arkit", "both"].includes(names)) {
      throw new Error(`names must be "oculus", "arkit" or "both", got ${JSON.stringify(names)}`);
    }
    this.client = client;
    this.table = table;
    this.names = names;
    this._start = null;    // the start message _segments was built for
    this._segments = [];   // [{morph, start, end}] on the sample clock
  }

  static async load(client, opts = {}, url = "/tables/morphs.tsv") {
    const r = await fetch(url);
    if (!r.ok) throw new Error(`${url}: HTTP ${r.status} ${await r.text()}`);
    return new MorphAdaptor(client, { ...opts, table: parseMorphTable(await r.text(), url) });
  }

  // The names this adaptor returns, in order.
  get targetNames() {
    return this.names === "oculus" ? OCULUS : this.names === "arkit" ? ARKIT : [...OCULUS, ...ARKIT];
  }

  // The Oculus morph of one phone: its own row, else its viseme class's row.
  morphOf(phone, viseme) {
    return this.table[(phone || "").replace(/[012]$/, "")] || this.table[viseme] || "viseme_sil";
  }

  // Per phone of a start message, its morph; runs of the same morph merged. The phones are
  // used rather than the viseme list because the server merges neighbouring phones of one
  // class (s t, n d) that Oculus keeps apart.
  segments(start) {
    const vis = start.visemes || [], out = [];
    let j = 0;
    for (const p of start.phones || vis) {
      while (j + 1 < vis.length && vis[j].end <= p.start) j++;
      const morph = this.morphOf(p.phone, p.viseme ?? (vis[j] ? vis[j].viseme : undefined));
      const last = out[out.length - 1];
      if (last && last.morph === morph && last.end === p.start) last.end = p.end;
      else out.push({ morph, start: p.start, end: p.end });
    }
    return out;
  }

  // Oculus viseme weights at a sample (they sum to 1; silence when nothing is playing).
  visemesAt(sample) {
    const w = Object.fromEntries(OCULUS.map((n) => [n, 0]));
    const u = this.client.utt;
    if (sample === null || sample === undefined || !u || !u.start) {
      w.viseme_sil = 1;
      return w;
    }
    if (this._start !== u.start) { this._start = u.start; this._segments = this.segments(u.start); }
    const list = this._segments;
    let lo = 0, hi = list.length - 1;   // the last segment starting at or before the sample
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (list[mid].start <= sample) lo = mid; else hi = mid - 1;
    }
    const e = list[lo];
    if (!e || sample < e.start || sample >= e.end) { w.viseme_sil = 1; return w; }
    const maxHalf = CROSSFADE_HALF_S * u.sr;
    const dur = (i) => list[i].end - list[i].start;
    const prev = lo > 0 && list[lo - 1].end === e.start ? lo - 1 : -1;
    const next = lo + 1 < list.length && list[lo + 1].start === e.end ? lo + 1 : -1;
    const hIn = prev < 0 ? 0 : Math.min(maxHalf, dur(prev) / 2, dur(lo) / 2);
    const hOut = next < 0 ? 0 : Math.min(maxHalf, dur(lo) / 2, dur(next) / 2);
    if (hIn > 0 && sample < e.start + hIn) {          // fading in from the previous segment
      const t = smooth((sample - (e.start - hIn)) / (2 * hIn));
      w[e.morph] += t; w[list[prev].morph] += 1 - t;
    } else if (hOut > 0 && sample >= e.end - hOut) {  // fading out to the next one
      const t = smooth((sample - (e.end - hOut)) / (2 * hOut));
      w[e.morph] += 1 - t; w[list[next].morph] += t;
    } else {
      w[e.morph] = 1;
    }
    return w;
  }

  // ARKit weights from the mouth measures at a sample (all 0 when nothing is playing).
  arkitAt(sample, visemes = this.visemesAt(sample)) {
    const w = Object.fromEntries(ARKIT.map((n) => [n, 0]));
    const mouth = sample === null || sample === undefined ? null : this.client.mouthAt(sample);
    if (!mouth) return w;
    const { lipGap: gap, width, jaw } = mouth;
    const speech = 1 - visemes.viseme_sil;   // rest shuts the lips too: that is not a closure
    const narrow = ramp(width, RANGES.narrow), round = ramp(gap, RANGES.rounding);
    const apart = ramp(gap - (jaw - RANGES.jawOpen[0]), RANGES.lipsApart);
    const set = (name, v) => {
      if (name in w) w[name] = clamp01(v);
      else { w[name + "Left"] = clamp01(v); w[name + "Right"] = clamp01(v); }
    };
    set("jawOpen", ramp(jaw, RANGES.jawOpen));
    set("mouthClose", ramp(gap, RANGES.mouthClose) * speech);
    set("mouthPress", ramp(gap, RANGES.mouthPress) * speech);
    set("mouthFunnel", narrow * round);
    set("mouthPucker", narrow * (1 - round));
    set("mouthStretch", ramp(width, RANGES.mouthStretch));
    set("mouthSmile", ramp(width, RANGES.mouthSmile));
    set("mouthLowerDown", apart);
    set("mouthUpperUp", apart * 0.5);   // the upper lip moves about half as far
    for (const [target, from] of Object.entries(ROLLS)) {
      set(target, Object.entries(from).reduce((s, [v, k]) => s + k * visemes[v], 0));
    }
    return w;
  }

  // {name: weight 0..1} at a sample (default: the one being heard now).
  weightsAt(sample = this.client.currentSample()) {
    const vis = this.visemesAt(sample);
    if (this.names === "oculus") return vis;
    const ark = this.arkitAt(sample, vis);
    return this.names === "arkit" ? ark : { ...vis, ...ark };
  }

  // Write the weights into a three.js mesh's morphTargetInfluences (names the mesh lacks
  // are skipped; ALIASES are tried first). Given an object with children (a glTF scene),
  // every mesh in it that has morph targets is driven. `weights` defaults to
  // weightsAt(sample); pass your own (say, scaled or mixed with emotions) to write those.
  // Returns the weights.
  apply(object, sample = this.client.currentSample(), weights = this.weightsAt(sample)) {
    const drive = (mesh) => {
      const dict = mesh.morphTargetDictionary, infl = mesh.morphTargetInfluences;
      if (!dict || !infl) return;
      for (const [name, v] of Object.entries(weights)) {
        let i = dict[name];
        if (i === undefined) {
          for (const alt of ALIASES[name] || []) if (dict[alt] !== undefined) { i = dict[alt]; break; }
        }
        if (i !== undefined) infl[i] = v;
      }
    };
    if (object.morphTargetDictionary) drive(object);
    else if (object.traverse) object.traverse(drive);
    return weights;
  }
}
