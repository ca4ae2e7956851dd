"""Mouth-motion bench (issue 4, "Must show").

Prints each figure beside its goal/peer, from a set of varied sentences run
through the real front end (``text_to_timeline``) at several speaking rates:

* bilabial closure: fraction of P/B/M phones whose ``lip_gap`` falls, during the
  phone, to <= 10% of the utterance's 95th-percentile gap (goal >= 95% at
  200 wpm, >= 90% at 300 wpm), per model;
* rate adaptation: mean peak ``jaw`` on open vowels, 300 vs 120 wpm (goal: spring
  at least 15% smaller; cosine shows no such drop);
* max node speed in mm/s vs the documented physiological limit (500 mm/s =
  0.5 m/s for lips at face scale);
* viseme changes per second, raw and with a hold (peers ~13/s raw, ~7/s held);
* cost: median time of ``mouth_for`` for a >= 20 s utterance, all nodes, 100 Hz
  (goal < 5 ms).

Run: ``.venv/bin/python bench/bench_mouth.py``
"""

from __future__ import annotations

import statistics
import time
from itertools import pairwise

import numpy as np

from lipclock.face.models import MOUTH_MODELS, mouth_for
from lipclock.face.visemes import visemes_for
from lipclock.speech.frontend import text_to_timeline
from lipclock.speech.phoneset import base

SENTENCES = [
    "My mom made a big apple pie for the party.",
    "Bob put the maps back in the blue box before lunch.",
    "Peter Piper picked a peck of pickled peppers.",
    "The boy from Bombay bought a bamboo umbrella by the pier.",
    "Please pass me the pepper and the bread, mister Brown.",
    "We will meet at the museum in March, maybe at five.",
    "A very brave violinist moved from Vermont to Boston.",
    "Time flies when the problem is simple and the team is happy.",
    "Father saw the large dog walk across the park at dawn.",
    "Improbable numbers bumped the premium up by a lump sum.",
]
OPEN_VOWELS = {"AA", "AE", "AO", "AW", "AY"}
BILABIALS = {"P", "B", "M"}
SPEED_LIMIT_MM_S = 500.0  # lips at face scale: 0.5 m/s (see docs/mouth.md)
HOLD_S = 0.08  # viseme hold: events shorter than this are absorbed by a neighbour


def closure_fraction(tl, track) -> tuple[int, int]:
    gap = track.measures["lip_gap"]
    fs = track.frame_samples()
    thresh = 0.10 * float(np.percentile(gap, 95))
    hit = total = 0
    for p in tl.phones:
        if base(p.phone) not in BILABIALS:
            continue
        lo, hi = np.searchsorted(fs, [p.start, p.end])
        if hi <= lo:  # phone shorter than a frame: use the nearest frame
            lo, hi = max(0, lo - 1), min(len(fs), lo + 1)
        total += 1
        hit += int(gap[lo:hi].min() <= thresh)
    return hit, total


def open_vowel_peaks(tl, track) -> list[float]:
    jaw = track.measures["jaw"]
    fs = track.frame_samples()
    out = []
    for p in tl.phones:
        if base(p.phone) in OPEN_VOWELS:
            lo, hi = np.searchsorted(fs, [p.start, p.end])
            if hi > lo:
                out.append(float(jaw[lo:hi].max()))
    return out


def max_speed_mm_s(track) -> float:
    d = np.diff(track.frames.astype(np.float64), axis=0)
    return float(np.hypot(d[..., 0], d[..., 1]).max() * track.rate_hz)


def viseme_rates(tl) -> tuple[float, float]:
    ev = visemes_for(tl)
    dur_s = tl.num_samples / tl.sample_rate
    raw = sum(1 for a, b in pairwise(ev) if a.viseme != b.viseme)
    hold = round(HOLD_S * tl.sample_rate)
    held: list[str] = []
    for e in ev:
        if e.end - e.start < hold and held:
            continue  # too short to show: keep the previous viseme
        if not held or held[-1] != e.viseme:
            held.append(e.viseme)
    return raw / dur_s, (len(held) - 1) / dur_s


def main() -> None:
    rates = (120, 200, 300)
    tls = {r: [text_to_timeline(s, rate_wpm=r) for s in SENTENCES] for r in rates}
    print(f"{len(SENTENCES)} sentences; models: {', '.join(MOUTH_MODELS)}")
    print("\nBilabial closure (P/B/M phones reaching <=10% of the p95 lip gap)")
    for model in MOUTH_MODELS:
        row = []
        for r in rates:
            h = t = 0
            for tl in tls[r]:
                a, b = closure_fraction(tl, mouth_for(tl, model))
                h, t = h + a, t + b
            row.append(f"{r} wpm {100 * h / t:5.1f}% ({h}/{t})")
        print(f"  {model:8s} " + "   ".join(row))
    print("  goal (spring): >= 95% at 200 wpm, >= 90% at 300 wpm")

    print("\nRate adaptation (mean peak jaw on open vowels, mm)")
    for model in MOUTH_MODELS:
        peaks = {r: statistics.mean(p for tl in tls[r] for p in
                                    open_vowel_peaks(tl, mouth_for(tl, model)))
                 for r in (120, 300)}
        drop = 100 * (1 - peaks[300] / peaks[120])
        print(f"  {model:8s} 120 wpm {peaks[120]:.2f}  300 wpm {peaks[300]:.2f}"
              f"  drop {drop:5.1f}%")
    print("  goal: spring drop >= 15%; cosine ~0%")

    print(f"\nMax node speed (mm/s, 100 Hz frames) vs limit {SPEED_LIMIT_MM_S:.0f}")
    for model in MOUTH_MODELS:
        row = [f"{r} wpm {max(max_speed_mm_s(mouth_for(tl, model)) for tl in tls[r]):6.0f}"
               for r in rates]
        print(f"  {model:8s} " + "   ".join(row))

    print(f"\nViseme changes per second (raw / with a {HOLD_S * 1000:.0f} ms hold)")
    for r in rates:
        vr = [viseme_rates(tl) for tl in tls[r]]
        print(f"  {r} wpm  {statistics.mean(v[0] for v in vr):5.1f}/s raw"
              f"  {statistics.mean(v[1] for v in vr):5.1f}/s held")
    print("  peers: ~13/s raw, ~7/s held")

    long_text, i = SENTENCES[0], 1
    tl = text_to_timeline(long_text)
    while tl.num_samples < 20 * tl.sample_rate:  # just past 20 s
        long_text += " " + SENTENCES[i % len(SENTENCES)]
        i += 1
        tl = text_to_timeline(long_text)
    print(f"\nCost: {tl.num_samples / tl.sample_rate:.1f} s utterance, 100 Hz, all nodes"
          " (median of 21 runs)")
    for model in MOUTH_MODELS:
        mouth_for(tl, model)  # warm-up (table load)
        times = []
        for _ in range(21):
            t0 = time.perf_counter()
            tr = mouth_for(tl, model)
            times.append(time.perf_counter() - t0)
        print(f"  {model:8s} {1000 * statistics.median(times):6.2f} ms"
              f"  ({tr.frames.shape[0]} frames x {tr.frames.shape[1]} nodes)  goal < 5 ms")


if __name__ == "__main__":
    main()
