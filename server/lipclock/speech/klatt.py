"""Klatt cascade/parallel formant synthesizer (Klatt 1980; Klatt & Klatt 1990).

Signal path, per sample::

    KLGLOTT88 flow (OQ, F0 + flutter) -> tilt low-pass ─┐
    aspiration noise (AH, + breathiness) ───────────────┴─> nasal zero -> nasal pole
        -> F6 -> F5 -> F4 -> F3 -> F2 -> F1   (cascade, for voiced sounds)
    frication noise (AF) -> F2..F6 with A2..A6, + bypass AB   (parallel, alternating signs)
    (cascade + parallel) -> first difference (radiation) -> gain -> soft limit -> int16

Resonators are Klatt's two-pole sections ``y = A x + B y1 + C y2`` with
``C = -exp(-2 pi BW T)``, ``B = 2 exp(-pi BW T) cos(2 pi F T)``; cascade sections
have unity gain at DC (``A = 1 - B - C``), parallel ones unity gain at their
peak, so A2..A6 read as levels. Formants at or above 0.45 x sample rate are
bypassed, so every supported rate (8-48 kHz) works.

Parameters come as 5 ms frames (klatt_params.py) and are interpolated linearly;
filter coefficients are recomputed every ~2 ms (``sample_rate // 500`` samples), on
blocks aligned to the absolute sample clock, so rendering in any chunking gives identical samples.
Noise comes from a seeded 32-bit LCG: the same input gives the same output.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import klatt_params as kp
from .voices import Voice

OUTPUT_GAIN = 36000.0  # chosen so loud vowels peak near -6 dBFS (tests check no clipping)
LIMIT = 30000.0  # soft limiter knee in int16 units

# state vector layout
_S_PHASE, _S_T0, _S_TE, _S_AVLAT, _S_TILT, _S_NLP1, _S_NLP2, _S_RAD, _S_SEED = range(9)
# (_S_NLP2 holds the parallel branch's quiet-block counter)
_S_RES = 9  # resonator memories start here: 2 per section
_N_CASC = 8  # NZ, NP, F6, F5, F4, F3, F2, F1
_P0 = 3 * _N_CASC  # first parallel coefficient
_N_PAR = 5  # F2..F6 parallel
STATE_SIZE = _S_RES + 2 * (_N_CASC + _N_PAR) + 2


@njit(cache=True, nogil=True)
def _db(x: float) -> float:
    return 0.0 if x <= 0.0 else 10.0 ** ((x - 60.0) / 20.0)


@njit(cache=True, nogil=True)
def _res(f: float, bw: float, sr: float, peak: bool, out: np.ndarray, i: int) -> None:
    """Write resonator coefficients (A, B, C) into out[i:i+3]."""
    if f <= 0.0 or f >= 0.45 * sr:
        out[i] = 1.0 if not peak else 0.0
        out[i + 1] = 0.0
        out[i + 2] = 0.0
        return
    r = math.exp(-math.pi * bw / sr)
    c = -r * r
    b = 2.0 * r * math.cos(2.0 * math.pi * f / sr)
    if peak:
        th = 2.0 * math.pi * f / sr
        a = (1.0 - r) * math.sqrt(1.0 - 2.0 * r * math.cos(2.0 * th) + r * r)
    else:
        a = 1.0 - b - c
    out[i] = a
    out[i + 1] = b
    out[i + 2] = c


@njit(cache=True, nogil=True)
def _render(frames: np.ndarray, sr: int, start: int, end: int, state: np.ndarray,
            voice: np.ndarray, out: np.ndarray) -> None:
    n_frames = frames.shape[0]
    n_par = frames.shape[1]
    block = max(8, sr // 500)  # coefficients every ~2 ms, on absolute-clock blocks
    p = np.empty(n_par)
    coef = np.zeros(3 * (_N_CASC + _N_PAR))
    mem = state[_S_RES:_S_RES + 2 * (_N_CASC + _N_PAR)].copy()
    breath, flutter, fscale = voice[0], voice[1], voice[2]
    srf = float(sr)
    # state in locals for speed; written back at the end
    phase, t0, te, av_latch = state[_S_PHASE], state[_S_T0], state[_S_TE], state[_S_AVLAT]
    tilt_y, nlp1, rad_prev = state[_S_TILT], state[_S_NLP1], state[_S_RAD]
    seed = int(state[_S_SEED])
    quiet_blocks = int(state[_S_NLP2])  # blocks since the parallel branch last had input
    av = ah = af = 0.0
    tilt_a = 0.0
    inv_a0 = 1.0
    par_amp = np.zeros(6)
    for n in range(start, end):
        if n == start or n % block == 0:
            b0 = n - n % block
            pos = b0 * kp_rate / srf
            k = int(pos)
            frac = pos - k
            if k >= n_frames - 1:
                k = n_frames - 2
                frac = 1.0
            for j in range(n_par):
                p[j] = frames[k, j] * (1.0 - frac) + frames[k + 1, j] * frac
            _res(p[18], p[19], srf, False, coef, 0)  # FNZ (used inverted)
            inv_a0 = 1.0 / coef[0] if coef[0] != 0.0 else 0.0
            _res(p[16], p[17], srf, False, coef, 3)  # FNP
            for j in range(6):
                fi = 5 - j  # F6 first
                _res(p[4 + fi] * fscale, p[10 + fi] * fscale, srf, False, coef, 6 + 3 * j)
            av = _db(p[1])
            ah = _db(p[2])
            af = _db(p[3])
            if af > 0.0:
                quiet_blocks = 0
            elif n % block == 0:
                quiet_blocks += 1
            # everything here depends only on the absolute block, never on chunking
            for j in range(6):
                par_amp[j] = _db(p[20 + j])
            if quiet_blocks < 10 or n == start:
                for j in range(5):  # parallel F2..F6
                    _res(p[5 + j] * fscale, p[11 + j] * fscale, srf, True, coef, _P0 + 3 * j)
            g = 10.0 ** (-p[27] / 20.0)
            if g >= 0.999:
                tilt_a = 0.0
            else:
                cw = math.cos(2.0 * math.pi * 3000.0 / srf)
                g2 = g * g
                qa = 1.0 - g2
                qb = 1.0 - g2 * cw
                disc = qb * qb - qa * qa
                tilt_a = (qb - math.sqrt(max(disc, 0.0))) / qa
        # --- voicing source: KLGLOTT88 flow, pitch-synchronous parameter latch
        if phase >= t0:
            phase -= t0
            f0 = p[0]
            tsec = n / srf
            fl = flutter / 50.0 * (math.sin(2 * math.pi * 12.7 * tsec)
                                   + math.sin(2 * math.pi * 7.1 * tsec)
                                   + math.sin(2 * math.pi * 4.7 * tsec)) / 100.0
            if f0 > 20.0:
                t0 = srf / (f0 * (1.0 + fl))
                av_latch = av
            else:
                t0 = srf / 100.0
                av_latch = 0.0
            oq = p[26] if p[26] > 0.05 else 0.5
            te = oq * t0
        flow = 0.0
        if phase < te:
            x = phase / te
            flow = 6.75 * (x * x - x * x * x)  # peak 1.0 at x = 2/3
        phase += 1.0
        tilt_y = (1.0 - tilt_a) * flow * av_latch + tilt_a * tilt_y
        # --- noise: two uniform draws (triangular), low-passed (-6 dB/oct)
        seed = (seed * 1103515245 + 12345) & 0x7FFFFFFF
        r1 = seed / 1073741823.5 - 1.0
        seed = (seed * 1103515245 + 12345) & 0x7FFFFFFF
        nlp1 = r1 + seed / 1073741823.5 - 1.0 + 0.75 * nlp1
        mod = 1.0 if (av_latch == 0.0 or phase <= te) else 0.5
        asp = (ah + breath * av_latch * 0.12) * nlp1 * mod * 0.012  # cascade gain is high
        # --- cascade: nasal zero, nasal pole, F5..F1
        x = tilt_y + asp
        y = (x - coef[1] * mem[0] - coef[2] * mem[1]) * inv_a0 if inv_a0 != 0.0 else x
        mem[1] = mem[0]
        mem[0] = x
        x = y
        for j in range(1, _N_CASC):
            i = 3 * j
            m = 2 * j
            y = coef[i] * x + coef[i + 1] * mem[m] + coef[i + 2] * mem[m + 1]
            mem[m + 1] = mem[m]
            mem[m] = y
            x = y
        total = x
        # --- parallel (frication), alternating signs avoid spectral zeros; skipped once
        # it has had no input for 10 blocks (~20 ms: its resonators have rung out)
        if quiet_blocks < 10:
            fric = af * nlp1 * mod * 0.1
            par = par_amp[5] * fric
            sign = 1.0
            for j in range(_N_PAR):
                i = _P0 + 3 * j
                m = 2 * (_N_CASC + j)
                y = coef[i] * fric + coef[i + 1] * mem[m] + coef[i + 2] * mem[m + 1]
                mem[m + 1] = mem[m]
                mem[m] = y
                par += sign * par_amp[j] * y
                sign = -sign
            total += par
        rad = total - rad_prev
        rad_prev = total
        s = rad * OUTPUT_GAIN_J
        a = abs(s)
        if a > LIMIT_J:
            s = math.copysign(LIMIT_J + (32767.0 - LIMIT_J) * math.tanh((a - LIMIT_J) /
                                                                      (32767.0 - LIMIT_J)), s)
        out[n - start] = s
    state[_S_PHASE], state[_S_T0], state[_S_TE], state[_S_AVLAT] = phase, t0, te, av_latch
    state[_S_TILT], state[_S_NLP1], state[_S_RAD] = tilt_y, nlp1, rad_prev
    state[_S_SEED] = float(seed)
    state[_S_NLP2] = float(quiet_blocks)
    state[_S_RES:_S_RES + 2 * (_N_CASC + _N_PAR)] = mem


kp_rate = float(kp.FRAME_RATE_HZ)
OUTPUT_GAIN_J = OUTPUT_GAIN
LIMIT_J = LIMIT


class KlattRenderer:
    """Renders frames to int16 audio incrementally; any chunking gives identical samples."""

    def __init__(self, frames: np.ndarray, sample_rate: int, voice: Voice, seed: int = 0) -> None:
        if frames.ndim != 2 or frames.shape[1] != kp.N_PARAMS or len(frames) < 2:
            raise ValueError(f"frames must be (n >= 2, {kp.N_PARAMS}), got {frames.shape}")
        self.frames = np.ascontiguousarray(frames, dtype=np.float64)
        self.sample_rate = int(sample_rate)
        self.voice = np.array([voice.breathiness, voice.flutter, voice.formant_scale])
        self.state = np.zeros(STATE_SIZE)
        self.state[_S_T0] = self.sample_rate / 100.0
        self.state[_S_PHASE] = self.state[_S_T0]  # start a period at sample 0
        self.state[_S_SEED] = float((seed * 2654435761 + 1) & 0x7FFFFFFF)
        self.position = 0

    def render_until(self, end_sample: int) -> np.ndarray:
        n = max(0, int(end_sample) - self.position)
        buf = np.empty(n, dtype=np.float64)
        if n:
            _render(self.frames, self.sample_rate, self.position, self.position + n,
                    self.state, self.voice, buf)
        self.position += n
        return np.rint(np.clip(buf, -32767, 32767)).astype(np.int16)


def render(frames: np.ndarray, sample_rate: int, voice: Voice, num_samples: int,
           seed: int = 0) -> np.ndarray:
    return KlattRenderer(frames, sample_rate, voice, seed).render_until(num_samples)
