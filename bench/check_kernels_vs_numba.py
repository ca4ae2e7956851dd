"""C kernels (lipclock._kernels) against the numba kernels they replaced.

Loads speech/klatt.py, face/spring.py, face/bigram.py and face/models.py as they were
at the last numba commit (from git; numba must be installed for this script only),
runs old and new on varied utterances (voices, rates, pitches, every sample rate) and
prints the largest absolute differences: audio before rounding and as int16, spring
node positions, bigram measures, and the node speed limit.

    .venv/bin/pip install numba && .venv/bin/python bench/check_kernels_vs_numba.py
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np

from lipclock import engine
from lipclock.config import Settings
from lipclock.face import bigram, models, spring
from lipclock.speech import klatt, tracks

NUMBA_COMMIT = "65cf94b"  # last commit with the numba kernels
ROOT = Path(__file__).resolve().parent.parent

CASES = [  # text, voice, rate_wpm, pitch_hz, sample_rate
    ("Ready.", "adult-low", 160, None, 16000),
    ("Please hold the door.", "adult-high", 160, None, 16000),
    ("The next train leaves at 9:45.", "adult-low", 200, 110, 22050),
    ("Thank you for visiting the museum today!", "adult-high", 120, None, 24000),
    ("Would you like to hear that again?", "adult-low", 300, None, 48000),
    ("Your order number is 1,024.", "adult-high", 250, 260, 8000),
    ("Elevators are on the left, past the cafe.", "adult-low", 140, 90, 16000),
    ("Mom made me move the map by the bay.", "adult-high", 180, None, 22050),
    ("She sells sea shells; sixty-six thistles, fresh fish.", "adult-low", 220, None, 48000),
    ("Zero, one, two, three, four, five, six, seven.", "adult-high", 90, None, 16000),
    ("Hmm.", "adult-low", 160, None, 24000),
    ("A quick brown fox jumps over the lazy dog.", "adult-low", 350, 70, 16000),
    ("Is it raining in Philadelphia on Tuesday?", "adult-high", 160, 300, 8000),
    ("Turn left at the fountain, then take the stairs up two floors.", "adult-low", 170,
     None, 22050),
    ("Wow! That's amazing.", "adult-high", 200, None, 48000),
    ("Measure twice, cut once.", "adult-low", 130, None, 24000),
    ("The gift shop closes at five thirty p.m.", "adult-high", 280, None, 16000),
    ("Visitors must wear a badge at all times.", "adult-low", 160, 140, 8000),
    ("Breathe in, breathe out, and relax.", "adult-high", 110, None, 22050),
    ("Xylophones and zithers vibrate; fricatives hiss.", "adult-low", 240, None, 48000),
]


def load_old(module: str, package: str) -> object:
    """Import a module's source from NUMBA_COMMIT under a private name in its package."""
    path = "server/" + module.replace(".", "/") + ".py"
    src = subprocess.run(["git", "show", f"{NUMBA_COMMIT}:{path}"], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    src = src.replace("cache=True, ", "")  # numba cannot cache code without a file
    name = f"{package}._numba_{module.rsplit('.', 1)[1]}"
    spec = importlib.util.spec_from_loader(name, loader=None)
    assert spec is not None
    mod = importlib.util.module_from_spec(spec)
    mod.__package__ = package
    sys.modules[name] = mod
    exec(compile(src, f"{NUMBA_COMMIT}:{path}", "exec"), mod.__dict__)
    return mod


def render_float(kernel: object, r: klatt.KlattRenderer, ends: list[int]) -> np.ndarray:
    """Audio before rounding, rendered chunk by chunk through the given kernel."""
    state = np.zeros(klatt.STATE_SIZE)
    state[:] = r.state
    out, pos = [], 0
    for end in ends:
        buf = np.empty(end - pos)
        kernel(r.frames, r.sample_rate, pos, end, state, r.voice, buf)  # type: ignore[operator]
        out.append(buf)
        pos = end
    return np.concatenate(out)


def main() -> None:
    old_klatt = load_old("lipclock.speech.klatt", "lipclock.speech")
    old_spring = load_old("lipclock.face.spring", "lipclock.face")
    old_bigram = load_old("lipclock.face.bigram", "lipclock.face")
    old_models = load_old("lipclock.face.models", "lipclock.face")
    worst = {k: 0.0 for k in ("audio float", "audio int16", "audio chunked float",
                              "spring nodes mm", "bigram measures mm", "speed limit mm",
                              "bigram _speed_limit")}
    n_samples = n_diff16 = 0
    for text, voice, wpm, pitch, sr in CASES:
        s = Settings(sample_rate=sr)
        req = engine.make_request(text, voice=voice, rate_wpm=wpm, pitch_hz=pitch, settings=s)
        w = engine.run_stages(engine.Work(req), engine.STAGES[:3])
        tl = w.timeline
        assert tl is not None
        frames = tracks.klatt_frames(tl, req.voice)
        n = tl.num_samples
        new16 = klatt.render(frames, sr, req.voice, n)
        old16 = old_klatt.render(frames, sr, req.voice, n)
        r = klatt.KlattRenderer(frames, sr, req.voice)
        ends = engine.chunk_bounds(tl)
        new_f = render_float(klatt._render, r, [n])
        old_f = render_float(old_klatt._render, r, [n])
        old_chunked = render_float(old_klatt._render, r, ends)
        new_chunked = render_float(klatt._render, r, ends)
        d16 = np.abs(new16.astype(np.int32) - old16.astype(np.int32))
        n_samples += n
        n_diff16 += int(np.count_nonzero(d16))
        worst["audio float"] = max(worst["audio float"], float(np.max(np.abs(new_f - old_f))))
        worst["audio int16"] = max(worst["audio int16"], float(d16.max()))
        worst["audio chunked float"] = max(worst["audio chunked float"],
                                           float(np.max(np.abs(new_chunked - old_chunked))))
        assert np.array_equal(new_chunked, new_f), "C kernel is not chunking-exact"
        for rate_hz in (30.0, 100.0, 250.0):
            d = spring.default_dynamics()
            sn, so = spring.spring_nodes(tl, rate_hz, d), old_spring.spring_nodes(
                tl, rate_hz, old_spring.default_dynamics())
            worst["spring nodes mm"] = max(worst["spring nodes mm"], float(np.abs(sn - so).max()))
            fs = models._frame_samples(tl, rate_hz)
            bn, bo = bigram.bigram_measures(tl, fs), old_bigram.bigram_measures(tl, fs)
            worst["bigram measures mm"] = max(worst["bigram measures mm"],
                                              float(np.abs(bn - bo).max()))
            for cosine in (False, True):
                nodes = models._interp(tl, rate_hz, cosine).astype(np.float64)
                step = models.MAX_NODE_SPEED_MM_S / rate_hz
                ln = models.limit_node_speed(nodes, step)
                lo = old_models.limit_node_speed(nodes, step)
                worst["speed limit mm"] = max(worst["speed limit mm"],
                                              float(np.abs(ln - lo).max()))
    rng = np.random.default_rng(7)
    for _ in range(200):
        wv = rng.random(int(rng.integers(1, 400))) * (rng.random() < 0.5)
        wv[rng.random(len(wv)) < 0.8] = 0.0
        step = float(rng.uniform(0.01, 0.5))
        worst["bigram _speed_limit"] = max(worst["bigram _speed_limit"], float(np.abs(
            bigram._speed_limit(wv, step) - old_bigram._speed_limit(wv, step)).max()))
    print(f"{len(CASES)} utterances, {n_samples} samples, sample rates "
          f"{sorted({c[4] for c in CASES})}")
    for k, v in worst.items():
        print(f"  max |C - numba| {k:22s} {v:.3g}")
    print(f"  int16 samples that differ: {n_diff16} of {n_samples}")


if __name__ == "__main__":
    main()
