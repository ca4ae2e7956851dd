"""The C kernels (lipclock._kernels) against slow pure-Python oracles on small seeded inputs.

Each oracle is the kernel's loop written out plainly in Python, in the same
arithmetic order, so agreement is to float rounding (on glibc it is exact).
The size checks in csrc/module.c must raise ValueError, never read out of bounds.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from lipclock import _kernels
from lipclock.face import bigram, models, spring
from lipclock.speech import klatt
from lipclock.speech import klatt_params as kp
from lipclock.speech.voices import get_voice


def close(a: np.ndarray, b: np.ndarray) -> None:
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-9)


# --- node speed limit (face/models.py) and bigram slope limit (face/bigram.py)

def limit_node_speed_ref(nodes: np.ndarray, max_step: float) -> np.ndarray:
    out = nodes.tolist()
    for k in range(1, len(out)):
        for i in range(len(out[k])):
            dx = out[k][i][0] - out[k - 1][i][0]
            dy = out[k][i][1] - out[k - 1][i][1]
            d = math.sqrt(dx * dx + dy * dy)
            if d > max_step:
                f = max_step / d
                out[k][i] = [out[k - 1][i][0] + dx * f, out[k - 1][i][1] + dy * f]
    return np.array(out)


def test_limit_node_speed_matches_oracle() -> None:
    rng = np.random.default_rng(1)
    for n_frames, n_nodes in ((1, 3), (2, 1), (40, 5), (200, 29)):
        nodes = rng.normal(0.0, 4.0, (n_frames, n_nodes, 2))
        got = models.limit_node_speed(nodes, 1.5)
        close(got, limit_node_speed_ref(nodes, 1.5))
        assert got is not nodes and not np.shares_memory(got, nodes)


def test_limit_node_speed_accepts_float32_and_views() -> None:
    nodes = np.random.default_rng(2).normal(0.0, 3.0, (30, 4, 2))
    view = nodes.astype(np.float32)[::2]  # not contiguous
    close(models.limit_node_speed(view, 0.8), limit_node_speed_ref(view.astype(np.float64), 0.8))


def speed_limit_ref(w: np.ndarray, step: float) -> np.ndarray:
    out = list(w)
    for k in range(1, len(out)):
        out[k] = max(out[k], out[k - 1] - step)
    for k in range(len(out) - 2, -1, -1):
        out[k] = max(out[k], out[k + 1] - step)
    return np.array(out)


def test_speed_limit_matches_oracle() -> None:
    rng = np.random.default_rng(3)
    for n in (1, 2, 17, 300):
        w = rng.random(n) * (rng.random(n) < 0.3)
        got = bigram._speed_limit(w, 0.07)
        close(got, speed_limit_ref(w, 0.07))
    row = np.zeros((3, 50))
    row[1, 25] = 1.0
    close(bigram._speed_limit(row[1], 0.1), speed_limit_ref(row[1], 0.1))
    assert row[1].sum() == 1.0  # the caller's array is left alone


# --- bigram curve stitching (face/bigram.py)

def stitch_ref(fs, bounds, ids, pose_id, ku, kw, nk, w):
    k0 = 0
    for i in range(len(ids)):
        a0, b0, b1 = bounds[i], bounds[i + 1], bounds[i + 2]
        while k0 < len(fs) and fs[k0] < a0:
            k0 += 1
        k = k0
        while k < len(fs) and fs[k] < b1:
            t = fs[k]
            u = (0.5 * (t - a0) / max(b0 - a0, 1.0) if t < b0
                 else 0.5 + 0.5 * (t - b0) / max(b1 - b0, 1.0))
            for j in range(pose_id.shape[1]):
                p = pose_id[ids[i], j]
                if p < 0:
                    continue
                m = 1
                while m < nk[ids[i], j] - 1 and ku[ids[i], j, m] < u:
                    m += 1
                u0, u1 = ku[ids[i], j, m - 1], ku[ids[i], j, m]
                w0, w1 = kw[ids[i], j, m - 1], kw[ids[i], j, m]
                x = min(max((u - u0) / (u1 - u0), 0.0), 1.0)
                w[p, k] = max(w[p, k], w0 + (w1 - w0) * x)
            k += 1


def random_curves(rng: np.random.Generator, n_keys: int, n_pose: int, n_knot: int,
                  n_poses_w: int) -> tuple[np.ndarray, ...]:
    pose_id = np.full((n_keys, n_pose), -1, np.int64)
    ku = np.zeros((n_keys, n_pose, n_knot))
    kw = np.zeros((n_keys, n_pose, n_knot))
    nk = np.zeros((n_keys, n_pose), np.int64)
    for i in range(n_keys):
        for j in range(int(rng.integers(1, n_pose + 1))):
            m = int(rng.integers(2, n_knot + 1))
            pose_id[i, j] = rng.integers(0, n_poses_w)
            ku[i, j, :m] = np.r_[0.0, np.sort(rng.uniform(0.01, 0.99, m - 2)), 1.0]
            kw[i, j, :m] = rng.random(m)
            nk[i, j] = m
    return pose_id, ku, kw, nk


def test_stitch_matches_oracle() -> None:
    rng = np.random.default_rng(4)
    for n_phones in (2, 3, 12):
        bounds = np.r_[0.0, np.cumsum(rng.integers(1, 4000, n_phones))].astype(np.float64)
        ids = rng.integers(0, 6, n_phones - 1)
        fs = np.arange(-160.0, bounds[-1] + 320.0, 160.0)
        curves = random_curves(rng, 6, 4, 5, 7)
        w_got, w_ref = np.zeros((7, len(fs))), np.zeros((7, len(fs)))
        bigram._stitch(fs, bounds, ids, *curves, w_got)
        stitch_ref(fs, bounds, ids, *curves, w_ref)
        close(w_got, w_ref)
        assert w_got.any()


def test_stitch_rejects_out_of_range_indices() -> None:
    rng = np.random.default_rng(5)
    pose_id, ku, kw, nk = random_curves(rng, 2, 2, 3, 3)
    pose_id[0, 0] = 2  # a row of w that the one-row w below lacks
    fs, bounds, w = np.arange(10.0), np.array([0.0, 5.0, 10.0]), np.zeros((3, 10))
    with pytest.raises(ValueError, match="ids"):
        bigram._stitch(fs, bounds, np.array([2]), pose_id, ku, kw, nk, w)
    with pytest.raises(ValueError, match="pose_id"):
        bigram._stitch(fs, bounds, np.array([0]), pose_id, ku, kw, nk, np.zeros((1, 10)))
    with pytest.raises(ValueError, match="bounds"):
        bigram._stitch(fs, bounds[:2], np.array([0]), pose_id, ku, kw, nk, w)


# --- mouth springs (face/spring.py)

def integrate_ref(vis_idx, targets, closure, rest, mass, k, c, k_cl, c_cl, lips, edges,
                  k_nb, lip_pairs, dt, frame_pos):
    x, v = rest.astype(np.float64).tolist(), [[0.0, 0.0] for _ in rest]
    out = []
    for s, vi in enumerate(vis_idx):
        t = targets[vi]
        ks = [k_cl if closure[vi] and lips[i] else k[i] for i in range(len(rest))]
        cs = [c_cl if closure[vi] and lips[i] else c[i] for i in range(len(rest))]
        f = [[ks[i] * (t[i][a] - x[i][a]) - cs[i] * v[i][a] for a in (0, 1)]
             for i in range(len(rest))]
        for i2, j2 in edges:
            for a in (0, 1):
                stretch = (x[j2][a] - x[i2][a]) - (t[j2][a] - t[i2][a])
                f[i2][a] += k_nb * stretch
                f[j2][a] -= k_nb * stretch
        for i in range(len(rest)):
            for a in (0, 1):
                v[i][a] += f[i][a] * (dt / mass[i])
                x[i][a] += v[i][a] * dt
        for up, lo in lip_pairs:
            if x[lo][1] > x[up][1]:
                x[lo][1] = x[up][1] = 0.5 * (x[lo][1] + x[up][1])
                v[lo][1] = v[up][1] = 0.5 * (v[lo][1] + v[up][1])
        while len(out) < len(frame_pos) and frame_pos[len(out)] <= s + 0.5:
            out.append([p[:] for p in x])
    while len(out) < len(frame_pos):
        out.append([p[:] for p in x])
    return np.array(out).reshape(len(frame_pos), len(rest), 2)


def test_spring_integrate_matches_oracle() -> None:
    rng = np.random.default_rng(6)
    n, n_vis, n_steps = 5, 3, 120
    rest = rng.normal(0.0, 5.0, (n, 2))
    targets = rest + rng.normal(0.0, 3.0, (n_vis, n, 2))
    targets[1, 3, 1] = targets[1, 4, 1] - 2.0  # viseme 1 pushes lower lip 4 above upper 3
    args = dict(vis_idx=np.repeat(rng.integers(0, n_vis, n_steps // 10), 10),
                targets=targets, closure=np.array([False, True, False]), rest=rest,
                mass=rng.uniform(0.002, 0.01, n), k=rng.uniform(5.0, 40.0, n),
                c=rng.uniform(0.05, 0.5, n), k_cl=60.0, c_cl=0.8,
                lips=np.array([False, False, True, True, True]),
                edges=np.array([[0, 1], [1, 2], [2, 3], [3, 4], [0, 4]]), k_nb=3.0,
                lip_pairs=np.array([[3, 4]]), dt=0.001,
                frame_pos=np.r_[np.arange(0.0, n_steps + 30.0, 7.3)])
    got = spring._integrate(**args)
    close(got, integrate_ref(**args))
    assert got.shape == (len(args["frame_pos"]), n, 2)


def test_spring_integrate_rejects_bad_indices() -> None:
    rest = np.zeros((3, 2))
    ok = dict(vis_idx=np.zeros(4, np.int64), targets=np.zeros((2, 3, 2)),
              closure=np.zeros(2, bool), rest=rest, mass=np.ones(3), k=np.ones(3),
              c=np.ones(3), k_cl=1.0, c_cl=1.0, lips=np.zeros(3, bool),
              edges=np.array([[0, 1]]), k_nb=1.0, lip_pairs=np.array([[1, 2]]), dt=1e-3,
              frame_pos=np.arange(3.0))
    spring._integrate(**ok)
    for key, bad in (("vis_idx", np.array([0, 2])), ("edges", np.array([[0, 3]])),
                     ("lip_pairs", np.array([[-1, 0]])), ("mass", np.ones(2)),
                     ("closure", np.zeros(3, bool))):
        with pytest.raises(ValueError):
            spring._integrate(**{**ok, key: bad})


# --- Klatt synthesis (speech/klatt.py)

def res_ref(f: float, bw: float, sr: float, peak: bool) -> list[float]:
    if f <= 0.0 or f >= 0.45 * sr:
        return [0.0 if peak else 1.0, 0.0, 0.0]
    r = math.exp(-math.pi * bw / sr)
    c = -r * r
    b = 2.0 * r * math.cos(2.0 * math.pi * f / sr)
    if peak:
        th = 2.0 * math.pi * f / sr
        return [(1.0 - r) * math.sqrt(1.0 - 2.0 * r * math.cos(2.0 * th) + r * r), b, c]
    return [1.0 - b - c, b, c]


def db_ref(x: float) -> float:
    return 0.0 if x <= 0.0 else 10.0 ** ((x - 60.0) / 20.0)


def render_ref(frames: np.ndarray, sr: int, n_samples: int, voice: np.ndarray,
               state0: np.ndarray) -> np.ndarray:
    """Klatt's loop (speech/klatt.py docstring) from sample 0, one sample at a time."""
    breath, flutter, fscale = voice
    block = max(8, sr // 500)
    phase, t0, te, av_latch, tilt_y, nlp1, quiet, rad_prev, seed = state0[:9]
    quiet, seed = int(quiet), int(seed)
    n_casc = 8  # NZ, NP, F6..F1
    mem = [0.0] * (2 * (n_casc + 5))
    casc: list[list[float]] = []
    par: list[list[float]] = []
    p: list[float] = []
    av = ah = af = tilt_a = 0.0
    inv_a0 = 1.0
    par_amp: list[float] = []
    out = np.empty(n_samples)
    for n in range(n_samples):
        if n % block == 0:
            pos = n * float(kp.FRAME_RATE_HZ) / sr
            k, frac = int(pos), pos - int(pos)
            if k >= len(frames) - 1:
                k, frac = len(frames) - 2, 1.0
            p = [frames[k, j] * (1.0 - frac) + frames[k + 1, j] * frac
                 for j in range(kp.N_PARAMS)]
            nz = res_ref(p[kp.FNZ], p[kp.BNZ], sr, False)
            inv_a0 = 1.0 / nz[0] if nz[0] != 0.0 else 0.0
            casc = [nz, res_ref(p[kp.FNP], p[kp.BNP], sr, False)]
            casc += [res_ref(p[kp.F1 + fi] * fscale, p[kp.B1 + fi] * fscale, sr, False)
                     for fi in (5, 4, 3, 2, 1, 0)]
            av, ah, af = db_ref(p[kp.AV]), db_ref(p[kp.AH]), db_ref(p[kp.AF])
            quiet = 0 if af > 0.0 else quiet + 1
            par_amp = [db_ref(p[kp.A2 + j]) for j in range(6)]
            if quiet < 10 or n == 0:
                par = [res_ref(p[kp.F2 + j] * fscale, p[kp.B2 + j] * fscale, sr, True)
                       for j in range(5)]
            g = 10.0 ** (-p[kp.TL] / 20.0)
            if g >= 0.999:
                tilt_a = 0.0
            else:
                cw = math.cos(2.0 * math.pi * 3000.0 / sr)
                qa, qb = 1.0 - g * g, 1.0 - g * g * cw
                tilt_a = (qb - math.sqrt(max(qb * qb - qa * qa, 0.0))) / qa
        if phase >= t0:
            phase -= t0
            ts = n / sr
            fl = flutter / 50.0 * (math.sin(2 * math.pi * 12.7 * ts) + math.sin(
                2 * math.pi * 7.1 * ts) + math.sin(2 * math.pi * 4.7 * ts)) / 100.0
            if p[kp.F0] > 20.0:
                t0, av_latch = sr / (p[kp.F0] * (1.0 + fl)), av
            else:
                t0, av_latch = sr / 100.0, 0.0
            te = (p[kp.OQ] if p[kp.OQ] > 0.05 else 0.5) * t0
        x = phase / te if phase < te else 0.0
        flow = 6.75 * (x * x - x * x * x) if phase < te else 0.0
        phase += 1.0
        tilt_y = (1.0 - tilt_a) * flow * av_latch + tilt_a * tilt_y
        seed = (seed * 1103515245 + 12345) & 0x7FFFFFFF
        r1 = seed / 1073741823.5 - 1.0
        seed = (seed * 1103515245 + 12345) & 0x7FFFFFFF
        nlp1 = r1 + seed / 1073741823.5 - 1.0 + 0.75 * nlp1
        mod = 1.0 if (av_latch == 0.0 or phase <= te) else 0.5
        xin = tilt_y + (ah + breath * av_latch * 0.12) * nlp1 * mod * 0.012
        y = (xin - (casc[0][1] * mem[0] + casc[0][2] * mem[1])) * inv_a0 if inv_a0 != 0.0 else xin
        mem[0:2] = [xin, mem[0]]
        for j in range(1, n_casc):
            a, b, c = casc[j]
            y = a * y + (b * mem[2 * j] + c * mem[2 * j + 1])
            mem[2 * j:2 * j + 2] = [y, mem[2 * j]]
        total = y
        if quiet < 10:
            fric = af * nlp1 * mod * 0.1
            total_par, sign = par_amp[5] * fric, 1.0
            for j in range(5):
                a, b, c = par[j]
                m = 2 * (n_casc + j)
                yp = (a * fric + c * mem[m + 1]) + b * mem[m]
                mem[m:m + 2] = [yp, mem[m]]
                total_par += sign * par_amp[j] * yp
                sign = -sign
            total += total_par
        s = (total - rad_prev) * 36000.0
        rad_prev = total
        if abs(s) > 30000.0:
            s = math.copysign(30000.0 + 2767.0 * math.tanh((abs(s) - 30000.0) / 2767.0), s)
        out[n] = s
    return out


def klatt_frames(rng: np.random.Generator, n: int) -> np.ndarray:
    """Voiced, whispered, fricative and silent stretches; a tilted voice; a nasal."""
    fr = np.zeros((n, kp.N_PARAMS))
    fr[:, kp.F0] = np.where(np.arange(n) % 9 < 6, rng.uniform(80.0, 220.0, n), 0.0)
    fr[:, kp.AV] = np.where(fr[:, kp.F0] > 0, rng.uniform(40.0, 62.0, n), 0.0)
    fr[:, kp.AH] = rng.uniform(0.0, 50.0, n) * (rng.random(n) < 0.4)
    fr[:, kp.AF] = rng.uniform(30.0, 60.0, n) * (np.arange(n) < n // 3)  # then quiet
    fr[:, kp.F1:kp.F6 + 1] = np.sort(rng.uniform(250.0, 5200.0, (n, 6)), axis=1)
    fr[:, kp.F6] = 6000.0  # above 0.45 x 8 kHz: bypassed at the lowest rate
    fr[:, kp.B1:kp.B6 + 1] = rng.uniform(50.0, 400.0, (n, 6))
    fr[:, [kp.FNP, kp.FNZ]] = np.c_[np.full(n, 270.0), rng.uniform(250.0, 450.0, n)]
    fr[:, [kp.BNP, kp.BNZ]] = 100.0
    fr[:, kp.A2:kp.AB + 1] = rng.uniform(0.0, 60.0, (n, 6))
    fr[:, kp.OQ] = rng.uniform(0.0, 0.8, n)
    fr[:, kp.TL] = rng.uniform(0.0, 20.0, n) * (rng.random(n) < 0.5)
    return fr


@pytest.mark.parametrize("sample_rate", [8000, 16000, 22050])
def test_render_matches_oracle(sample_rate: int) -> None:
    rng = np.random.default_rng(sample_rate)
    fr = klatt_frames(rng, 16)
    n = int(0.07 * sample_rate)  # 14 frames, past the frication and its 10 quiet blocks
    voice = get_voice("adult-low")
    r = klatt.KlattRenderer(fr, sample_rate, voice, seed=3)
    state0 = r.state.copy()
    whole = np.empty(n)
    klatt._render(r.frames, sample_rate, 0, n, r.state, r.voice, whole)
    ref = render_ref(fr, sample_rate, n, r.voice, state0)
    close(whole, ref)
    assert np.abs(ref).max() > 100.0  # the oracle makes sound, so the check means something
    # chunked at odd places, the same samples exactly
    state, pos, parts = state0.copy(), 0, []
    for end in (1, 7, 8, 150, 151, n - 9, n):
        buf = np.empty(end - pos)
        klatt._render(r.frames, sample_rate, pos, end, state, r.voice, buf)
        parts.append(buf)
        pos = end
    assert np.array_equal(np.concatenate(parts), whole)
    assert np.array_equal(state, r.state)


def test_render_rejects_bad_buffers() -> None:
    r = klatt.KlattRenderer(klatt_frames(np.random.default_rng(0), 4), 16000,
                            get_voice("adult-low"))
    out = np.empty(100)
    with pytest.raises(ValueError, match="out"):
        klatt._render(r.frames, 16000, 0, 101, r.state, r.voice, out)
    with pytest.raises(ValueError, match="state"):
        klatt._render(r.frames, 16000, 0, 10, r.state[:-1].copy(), r.voice, out)
    with pytest.raises(ValueError, match="frames"):
        _kernels.klatt_render(r.frames, 27, 16000, 0, 10, r.state, r.voice, out)
    with pytest.raises(ValueError, match="2 frames"):
        klatt._render(r.frames[:1].copy(), 16000, 0, 10, r.state, r.voice, out)
    with pytest.raises(ValueError, match="range"):
        klatt._render(r.frames, 16000, 10, 5, r.state, r.voice, out)
    with pytest.raises((TypeError, ValueError, BufferError)):  # read-only output
        out.flags.writeable = False
        klatt._render(r.frames, 16000, 0, 10, r.state, r.voice, out)


def test_kernels_reject_wrong_dtypes_and_sizes() -> None:
    """The glue checks item types itself: a wrong dtype is a TypeError, not reinterpreted bytes."""
    r = klatt.KlattRenderer(klatt_frames(np.random.default_rng(0), 4), 16000,
                            get_voice("adult-low"))
    out = np.empty(10)
    with pytest.raises(TypeError, match="frames"):
        _kernels.klatt_render(r.frames.astype(np.float32), 28, 16000, 0, 10, r.state, r.voice,
                              out)
    with pytest.raises(TypeError, match="state"):
        _kernels.klatt_render(r.frames, 28, 16000, 0, 10, r.state.view(np.int64), r.voice, out)
    with pytest.raises(ValueError, match="frames"):  # n_par * 8 would wrap around to 224
        _kernels.klatt_render(np.zeros(56), 2**61 + 28, 16000, 0, 10, r.state, r.voice, out)
    with pytest.raises(TypeError, match="w"):
        _kernels.bigram_speed_limit(bytearray(16), 0.1)
    with pytest.raises(TypeError, match="nodes"):
        _kernels.limit_node_speed(np.zeros((3, 2, 2), np.int64), 2, 1.0)
    with pytest.raises(ValueError, match="nodes"):  # 16 * 2**60 wraps to 0: was a SIGFPE
        _kernels.limit_node_speed(np.zeros(4), 2**60, 1.0)
    curves = random_curves(np.random.default_rng(7), 2, 2, 3, 3)
    fs, bounds, w = np.arange(10.0), np.array([0.0, 5.0, 10.0]), np.zeros((3, 10))
    with pytest.raises(TypeError, match="ids"):
        _kernels.bigram_stitch(fs, bounds, np.array([0], np.int32), curves[0], curves[1],
                               curves[2], curves[3], 2, w)
    ok = dict(vis_idx=np.zeros(4, np.int64), targets=np.zeros((2, 3, 2)),
              closure=np.zeros(2, bool), rest=np.zeros((3, 2)), mass=np.ones(3), k=np.ones(3),
              c=np.ones(3), k_cl=1.0, c_cl=1.0, lips=np.zeros(3, bool),
              edges=np.array([[0, 1]]), k_nb=1.0, lip_pairs=np.array([[1, 2]]), dt=1e-3,
              frame_pos=np.arange(3.0), out=np.empty((3, 3, 2)))
    _kernels.spring_integrate(*ok.values())
    for key, bad in (("closure", np.zeros(2, np.uint8)), ("edges", np.array([[0, 1]], np.int32)),
                     ("out", np.empty((3, 3, 2), np.float32))):
        with pytest.raises(TypeError, match=key):
            _kernels.spring_integrate(*{**ok, key: bad}.values())

