"""Klatt parameter frames: the column layout shared by tracks.py and klatt.py.

One frame every 5 ms (``FRAME_RATE_HZ``); frame k stands at sample
``round(k * sample_rate / FRAME_RATE_HZ)``. Frequencies and bandwidths in Hz,
amplitudes in dB (0 = off; about 60 = full), open quotient as a fraction.
Parameter names follow Klatt (1980) Table I.
"""

from __future__ import annotations

FRAME_RATE_HZ = 200

NAMES = (
    "F0",  # fundamental frequency, Hz (0 = no voicing)
    "AV",  # voicing amplitude, dB
    "AH",  # aspiration amplitude, dB
    "AF",  # frication amplitude, dB
    "F1", "F2", "F3", "F4", "F5", "F6",
    "B1", "B2", "B3", "B4", "B5", "B6",
    "FNP", "BNP", "FNZ", "BNZ",  # nasal pole / zero pair (equal = cancelled)
    "A2", "A3", "A4", "A5", "A6", "AB",  # parallel-branch amplitudes, dB (AB: bypass)
    "OQ",  # KLGLOTT88 open quotient
    "TL",  # spectral tilt, dB down at 3 kHz
)
N_PARAMS = len(NAMES)
IDX = {name: i for i, name in enumerate(NAMES)}
(F0, AV, AH, AF, F1, F2, F3, F4, F5, F6, B1, B2, B3, B4, B5, B6, FNP, BNP, FNZ, BNZ,
 A2, A3, A4, A5, A6, AB, OQ, TL) = range(N_PARAMS)


def frame_sample(k: int, sample_rate: int) -> int:
    return round(k * sample_rate / FRAME_RATE_HZ)


def n_frames_for(num_samples: int, sample_rate: int) -> int:
    """Frames needed so the last sample lies before the last frame."""
    return int(num_samples * FRAME_RATE_HZ // sample_rate) + 2
