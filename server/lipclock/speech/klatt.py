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
Noise comes from a seeded 31-bit LCG: the same input gives the same output.
The per-sample loop is C (``csrc/klatt.c``, in the ``lipclock._kernels`` module).
"""

from __future__ import annotations

import numpy as np

from .. import _kernels
from . import klatt_params as kp
from .voices import Voice

# state vector layout (csrc/kernels.h names the same slots KS_*)
_S_PHASE, _S_T0, _S_TE, _S_AVLAT, _S_TILT, _S_NLP1, _S_NLP2, _S_RAD, _S_SEED = range(9)
# (_S_NLP2 holds the parallel branch's quiet-block counter)
_S_RES = 9  # resonator memories start here: 2 per section
_N_CASC = 8  # NZ, NP, F6, F5, F4, F3, F2, F1
_P0 = 3 * _N_CASC  # first parallel coefficient
_N_PAR = 5  # F2..F6 parallel
STATE_SIZE = _S_RES + 2 * (_N_CASC + _N_PAR) + 2

if STATE_SIZE != _kernels.KLATT_STATE_SIZE:  # csrc/kernels.h must agree with this layout
    raise ImportError("lipclock._kernels is stale: rebuild it (pip install -e .)")


def _render(frames: np.ndarray, sr: int, start: int, end: int, state: np.ndarray,
            voice: np.ndarray, out: np.ndarray) -> None:
    """Render samples [start, end) into ``out`` (float64, before rounding); updates ``state``.

    ``frames`` is (n >= 2, N_PARAMS) float64; ``state`` (STATE_SIZE,) and ``voice``
    (breathiness, flutter, formant scale) float64; all C-contiguous.
    """
    _kernels.klatt_render(frames, frames.shape[1], sr, start, end, state, voice, out)


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
