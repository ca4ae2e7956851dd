"""Parameter tracks: Timeline -> one Klatt parameter frame every 5 ms.

Per-phone targets come from ``data/klatt_targets.tsv``. The rules that make
them speech (after Klatt 1980 and the Holmes-Mattingly-Shearme boundary
scheme used by rule synthesizers):

* formant transitions: at each consonant-vowel boundary the formants start at a
  locus mix ``k * consonant + (1 - k) * vowel`` and move to the vowel target
  over 40-60 ms; liquids and glides move more slowly, obstruents jump;
* stops are closure, then a release burst shaped by place (parallel amplitudes),
  then for voiceless stops before a voiced sound an aspiration interval (VOT
  ~55 ms stressed, ~35 ms unstressed) that replaces the start of the next
  phone's voicing; voiced stops keep a weak voice bar and voice at release;
* nasals use the nasal pole/zero pair (murmur) and nasalise the edges of
  neighbouring vowels;
* fricative noise is shaped by place via A2..A6 and bypass AB;
* diphthongs glide between two targets in the middle of the vowel;
* a vowel-initial word after a pause or a vowel gets a brief glottal-stop dip;
* unstressed vowels are reduced toward schwa and are 3 dB weaker;
* smoothing touches AV only; bursts and frication edges stay sharp.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from ..errors import TableError
from ..tables import finite_float, iter_tsv, package_file
from . import klatt_params as kp
from .phoneset import PAUSE, info, phones
from .timeline import Timeline
from .voices import Voice

COLS = ("F1", "F2", "F3", "B1", "B2", "B3", "AV", "AF", "AH", "A2", "A3", "A4", "A5", "A6",
        "AB", "FNZ")
_FORM = 7  # F1 F2 F3 B1 B2 B3 FNZ are blended with transitions


@dataclass(frozen=True, slots=True)
class Target:
    phone: str
    values: dict[str, float]
    start: np.ndarray  # (7,) F1 F2 F3 B1 B2 B3 FNZ at the start
    end: np.ndarray  # same at the end (differs for diphthongs)


def load_targets(path: Path) -> dict[str, Target]:
    known = set(phones()) - {PAUSE} | {"AX"}
    out: dict[str, Target] = {}
    for line, fields in iter_tsv(path):
        name = fields[0]
        if name not in known:
            raise TableError(path, line, f"unknown phone {name!r}")
        if len(fields) not in (len(COLS) + 1, len(COLS) + 4):
            raise TableError(path, line, f"expected {len(COLS) + 1} or {len(COLS) + 4} columns, "
                                         f"got {len(fields)}")
        nums = [finite_float(path, line, c, v) for c, v in zip(COLS, fields[1:], strict=False)]
        vals = dict(zip(COLS, nums, strict=True))
        start = np.array([vals["F1"], vals["F2"], vals["F3"], vals["B1"], vals["B2"], vals["B3"],
                          vals["FNZ"]])
        end = start.copy()
        if len(fields) == len(COLS) + 4:
            end[:3] = [finite_float(path, line, "F*b", v) for v in fields[len(COLS) + 1:]]
        if np.any(start[:6] <= 0) or np.any(end[:3] <= 0):
            raise TableError(path, line, "formants and bandwidths must be positive")
        out[name] = Target(name, vals, start, end)
    missing = sorted(known - set(out))
    if missing:
        raise TableError(path, 1, f"no targets for: {' '.join(missing)}")
    return out


@cache
def targets() -> dict[str, Target]:
    return load_targets(package_file("lipclock.speech", "data/klatt_targets.tsv"))


# Locus weight k: how strongly a consonant pulls the boundary formants toward itself.
_LOCUS_K = {"stop": 0.55, "affricate": 0.5, "fricative": 0.5, "nasal": 0.5, "liquid": 0.45,
            "glide": 0.6, "aspirate": 0.0}
# Transition durations (s) inside a phone of this class, from a boundary to its target.
_TRANS_S = {"vowel": 0.05, "diphthong": 0.05, "liquid": 0.04, "glide": 0.04, "nasal": 0.02,
            "stop": 0.01, "affricate": 0.01, "fricative": 0.015, "aspirate": 0.01,
            "silence": 0.0}
_DEFAULTS = {kp.F4: 3300.0, kp.F5: 3750.0, kp.F6: 4900.0, kp.B4: 250.0, kp.B5: 200.0,
             kp.B6: 1000.0, kp.FNP: 270.0, kp.BNP: 100.0, kp.FNZ: 270.0, kp.BNZ: 100.0}
# Release burst length by place: labial bursts are brief, velar ones long and
# often double (Fant 1973; Stevens 1998, ch. 7).
_BURST_S = {"P": 0.006, "B": 0.005, "T": 0.012, "D": 0.010, "K": 0.020, "G": 0.016}
# /s z/ noise peaks above the default F6 (4.9 kHz): move the F6 pole up for them.
_HIGH_F6_HZ = {"S": 6000.0, "Z": 6000.0}
_SONORANT = {"vowel", "diphthong", "liquid", "glide", "nasal"}


def _target_for(phone: str) -> Target:
    t = targets()
    b = phone.rstrip("012")
    if b == "AH" and phone.endswith("0"):
        return t["AX"]
    tgt = t[b]
    if phone.endswith("0") and b not in ("ER", "IY", "IH", "UW", "OW"):
        ax = t["AX"]  # reduce unstressed vowels 30% toward schwa
        return Target(tgt.phone, tgt.values, 0.7 * tgt.start + 0.3 * ax.start,
                      0.7 * tgt.end + 0.3 * ax.end)
    return tgt


def klatt_frames(timeline: Timeline, voice: Voice) -> np.ndarray:
    """Frames (n, N_PARAMS) float32 covering the timeline; see klatt_params for columns."""
    sr = timeline.sample_rate
    n = kp.n_frames_for(timeline.num_samples, sr)
    fs = np.round(np.arange(n) * (sr / kp.FRAME_RATE_HZ)).astype(np.int64)
    out = np.zeros((n, kp.N_PARAMS), dtype=np.float64)
    for col, v in _DEFAULTS.items():
        out[:, col] = v
    out[:, kp.OQ] = voice.open_quotient
    out[:, kp.TL] = voice.tilt_db
    out[:, kp.F0] = timeline.f0_at(fs)
    ph = timeline.phones
    if not ph:
        return out.astype(np.float32)
    cls = [info(p.phone).cls for p in ph]
    tg = [None if p.is_pause else _target_for(p.phone) for p in ph]
    # HH takes the formants of what follows it
    for i, p in enumerate(ph):
        if p.base == "HH":
            nxt = next((tg[j] for j in range(i + 1, len(ph)) if tg[j] is not None
                        and cls[j] in ("vowel", "diphthong", "glide", "liquid")), None)
            if nxt is not None:
                assert tg[i] is not None
                tg[i] = Target("HH", tg[i].values, nxt.start.copy(), nxt.start.copy())
    starts, ends = _steady(tg)
    bounds = _boundaries(cls, starts, ends)
    aspiration_until = [-1] * len(ph)
    for i, p in enumerate(ph):
        lo, hi = np.searchsorted(fs, [p.start, p.end])
        if hi <= lo:
            continue
        t = (fs[lo:hi] - p.start) / sr
        dur = max(p.num_samples / sr, 1e-3)
        _formants(out, lo, hi, t, dur, starts[i], ends[i], bounds[i], bounds[i + 1], cls, i, ph)
        _sources(out, lo, hi, t, dur, p.phone, cls, tg, i, ph, sr, aspiration_until)
    _glottal_stops(out, fs, ph, cls)
    # smooth voicing onsets/offsets only (never AF/AH/A*: keeps bursts sharp)
    av = out[:, kp.AV].copy()
    out[1:-1, kp.AV] = 0.25 * av[:-2] + 0.5 * av[1:-1] + 0.25 * av[2:]
    return out.astype(np.float32)


def _steady(tg: list[Target | None]) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Start/end formant vectors; pauses borrow their neighbours' so nothing moves in silence."""
    n = len(tg)
    starts: list[np.ndarray | None] = [t.start if t else None for t in tg]
    ends: list[np.ndarray | None] = [t.end if t else None for t in tg]
    for i in range(n):
        if starts[i] is None:
            nb = next((starts[j] for j in range(i + 1, n) if starts[j] is not None), None)
            if nb is None:
                nb = next((ends[j] for j in range(i - 1, -1, -1) if ends[j] is not None), None)
            if nb is None:
                nb = np.array([500.0, 1500.0, 2500.0, 80.0, 100.0, 150.0, 270.0])
            starts[i] = ends[i] = nb
    return starts, ends  # type: ignore[return-value]


def _boundaries(cls: list[str], starts: list[np.ndarray],
                ends: list[np.ndarray]) -> list[np.ndarray]:
    """Formant values at each phone boundary (index i = start of phone i)."""
    n = len(cls)
    out = [starts[0]]
    for i in range(1, n):
        a, b = cls[i - 1], cls[i]
        left, right = ends[i - 1], starts[i]
        if a == "silence":
            v = right.copy()
        elif b == "silence":
            v = left.copy()
        else:
            a_cons = a not in ("vowel", "diphthong")
            b_cons = b not in ("vowel", "diphthong")
            if a_cons and not b_cons:
                k = _LOCUS_K.get(a, 0.5)
                v = k * left + (1 - k) * right
            elif b_cons and not a_cons:
                k = _LOCUS_K.get(b, 0.5)
                v = k * right + (1 - k) * left
            else:
                v = 0.5 * (left + right)
            if a == "nasal" or b == "nasal":
                v[6] = 360.0  # nasalised transition
        out.append(v)
    out.append(ends[-1])
    return out


def _formants(out: np.ndarray, lo: int, hi: int, t: np.ndarray, dur: float, start: np.ndarray,
              end: np.ndarray, lb: np.ndarray, rb: np.ndarray, cls: list[str], i: int,
              ph: tuple) -> None:
    c = cls[i]
    x = np.clip((t / dur - 0.2) / 0.6, 0.0, 1.0)
    glide = x * x * (3 - 2 * x)  # smoothstep between the diphthong's two targets
    base = start[None, :] + (end - start)[None, :] * glide[:, None]
    tr = min(_TRANS_S.get(c, 0.02), 0.5 * dur)
    if c in ("vowel", "diphthong") and i > 0 and cls[i - 1] in ("stop", "nasal", "affricate"):
        tr = min(0.06, 0.5 * dur)  # CV transitions from stops/nasals are the long, audible ones
    if tr > 0:
        wl = np.clip(1.0 - t / tr, 0.0, 1.0)[:, None]
        wr = np.clip(1.0 - (dur - t) / tr, 0.0, 1.0)[:, None]
        vals = base + (lb - start)[None, :] * wl + (rb - end)[None, :] * wr
    else:
        vals = base
    if c in ("stop", "affricate"):
        vals = np.repeat(((lb + rb) * 0.5)[None, :], hi - lo, axis=0) if c == "stop" else vals
    cols = [kp.F1, kp.F2, kp.F3, kp.B1, kp.B2, kp.B3, kp.FNZ]
    out[lo:hi, cols] = vals


_PAR = (("AF", kp.AF), ("A2", kp.A2), ("A3", kp.A3), ("A4", kp.A4), ("A5", kp.A5),
        ("A6", kp.A6), ("AB", kp.AB))


def _sources(out: np.ndarray, lo: int, hi: int, t: np.ndarray, dur: float, phone: str,
             cls: list[str], tg: list, i: int, ph: tuple, sr: int,
             aspiration_until: list[int]) -> None:
    c = cls[i]
    tgt = tg[i]
    if tgt is None:
        return  # pause: all sources off
    v = tgt.values
    nxt = cls[i + 1] if i + 1 < len(cls) else "silence"
    if c in ("vowel", "diphthong", "liquid", "glide", "nasal"):
        av = v["AV"] - (3.0 if phone.endswith("0") else 0.0)
        out[lo:hi, kp.AV] = av
        if nxt == "silence" and c in ("vowel", "diphthong"):
            fall = np.clip((t / dur - 0.6) / 0.4, 0.0, 1.0)
            out[lo:hi, kp.AV] = av - 8.0 * fall  # phrase-final decay
    elif c == "aspirate":
        out[lo:hi, kp.AH] = v["AH"]
    elif c == "fricative":
        out[lo:hi, kp.AV] = v["AV"]
        if phone in _HIGH_F6_HZ:
            out[lo:hi, kp.F6] = _HIGH_F6_HZ[phone]
        for name, col in _PAR:
            out[lo:hi, col] = v[name]
    elif c in ("stop", "affricate"):
        voiced = info(phone).voiced
        burst_s = _BURST_S.get(phone, 0.01) if c == "stop" else 0.5 * dur
        in_burst = t >= dur - min(burst_s, 0.5 * dur)
        if voiced and i > 0 and cls[i - 1] != "silence":
            out[lo:hi, kp.AV] = np.where(in_burst, v["AV"], 38.0)  # voice bar in closure
        release = nxt not in ("silence",)
        weaker = 0.0 if release else 8.0
        for name, col in _PAR:
            out[lo:hi, col] = np.where(in_burst, max(0.0, v[name] - weaker) if v[name] else 0.0,
                                       0.0)
        if c == "affricate" and voiced:
            out[lo:hi, kp.AV] = np.where(in_burst, v["AV"], 0.0)
    # a voiceless stop before a voiced sound aspirates into the next phone
    if info(phone).cls == "stop" and not info(phone).voiced and i + 1 < len(ph) \
            and nxt in _SONORANT:
        nxt_ph = ph[i + 1]
        stressed = nxt_ph.phone[-1:] in ("1", "2")
        vot_s = 0.055 if stressed else 0.035
        vot = min(int(vot_s * sr), nxt_ph.num_samples // 2)
        aspiration_until[i + 1] = nxt_ph.start + vot
    if aspiration_until[i] > 0:
        fs_here = ph[i].start + (t * sr).astype(np.int64)
        asp = fs_here < aspiration_until[i]
        out[lo:hi, kp.AH] = np.where(asp, 58.0, out[lo:hi, kp.AH])
        out[lo:hi, kp.AV] = np.where(asp, 0.0, out[lo:hi, kp.AV])


def _glottal_stops(out: np.ndarray, fs: np.ndarray, ph: tuple, cls: list[str]) -> None:
    """Vowel-initial words after a pause or a vowel start with a brief AV dip (glottal stop)."""
    for i in range(1, len(ph)):
        p = ph[i]
        if cls[i] not in ("vowel", "diphthong") or p.word < 0:
            continue
        if ph[i - 1].word == p.word:
            continue
        if cls[i - 1] in ("vowel", "diphthong", "silence"):
            lo, hi = np.searchsorted(fs, [p.start, p.start + (p.end - p.start) // 4])
            out[lo:hi, kp.AV] -= 12.0
