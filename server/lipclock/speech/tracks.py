"""Parameter tracks: Timeline -> one Klatt parameter frame every 5 ms.

Per-phone targets come from ``data/klatt_targets.tsv``. The rules that make
them speech (after Klatt 1980 and the Holmes-Mattingly-Shearme boundary
scheme used by rule synthesizers):

* formant transitions: at each consonant-vowel boundary the formants start at a
  locus mix ``k * consonant + (1 - k) * vowel`` and move to the vowel target
  over 40-60 ms; liquids and glides move more slowly, obstruents jump;
* stops are closure, then a decaying release burst shaped by place (parallel
  amplitudes, formants at the locus of the vowel released into), then for
  onset voiceless stops before a voiced sound an aspiration interval (VOT
  ~55 ms stressed, ~35 ms unstressed) that replaces the start of the next
  phone's voicing; voiced stops keep a weak voice bar and voice at release;
  coda stops are released weakly and never aspirate into the next word;
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
# The release transient is strongest at the release and dies away over the burst
# (Stevens 1998 ch. 7): AF falls this many dB from the first to the last burst frame.
_BURST_DECAY_DB = 12.0
# Word-final stops are weakly released in connected speech (often unreleased).
_CODA_BURST_DB = 10.0
# Voice bar: low-frequency voicing radiated through the walls during a voiced
# closure, some 30 dB below the vowel (at 25 dB below, bench/phone_confusions.py
# heard voiced stops as voiced fricatives).
_VOICE_BAR_DB = 30.0


def _coda(ph: tuple, cls: list[str], i: int) -> bool:
    """Phone i ends its word's syllable: a pause, another word or a consonant follows."""
    if i + 1 >= len(ph) or cls[i + 1] == "silence":
        return True
    return cls[i + 1] not in ("vowel", "diphthong", "liquid", "glide")


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
    """Frames (n, N_PARAMS) float32 covering the timeline; see klatt_params for columns.

    Per-phone quantities are built once, then spread over frames by each frame's
    phone index, so the cost is a few numpy operations per utterance.
    """
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
    tg: list[Target | None] = [None if p.is_pause else _target_for(p.phone) for p in ph]
    for i, p in enumerate(ph):  # HH takes the formants of what follows it
        if p.base == "HH":
            nxt = next((tg[j] for j in range(i + 1, len(ph)) if tg[j] is not None
                        and cls[j] in ("vowel", "diphthong", "glide", "liquid")), None)
            if nxt is not None and tg[i] is not None:
                tg[i] = Target("HH", tg[i].values, nxt.start.copy(), nxt.start.copy())
    starts, ends = _steady(tg)
    bounds = _boundaries(cls, starts, ends, [p.base for p in ph])
    n_ph = len(ph)
    p_start = np.array([p.start for p in ph], dtype=np.int64)
    p_end = np.array([p.end for p in ph], dtype=np.int64)
    pidx = np.clip(np.searchsorted(p_end, fs, side="right"), 0, n_ph - 1)
    t = (fs - p_start[pidx]) / sr
    dur = np.maximum((p_end - p_start) / sr, 1e-3)[pidx]
    _formants(out, t, dur, pidx, np.array(starts), np.array(ends), np.array(bounds), cls)
    # The synthesizer scales F1..F6 by the voice's tract length but not the nasal
    # pair. The murmur's zero exists to cancel F1 (Klatt 1980), so where it is in
    # use (not parked on the pole) it must move with the scaled F1.
    nz = out[:, kp.FNZ]
    out[:, kp.FNZ] = np.where(np.abs(nz - out[:, kp.FNP]) > 1.0, nz * voice.formant_scale, nz)
    _sources(out, fs, t, dur, pidx, cls, tg, ph, sr)
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


_VELAR = frozenset({"K", "G", "NG"})


def _velar_pinch(v: np.ndarray, vowel: np.ndarray) -> np.ndarray:
    """Velar loci follow the vowel: F2 starts just above the vowel's F2 and F3 comes down
    to meet it (the 'velar pinch', Stevens 1998 ch. 7)."""
    out = v.copy()
    f2 = float(np.clip(vowel[1] * 1.08 + 120.0, 1300.0, 2400.0))
    out[1] = f2
    out[2] = min(float(vowel[2]), f2 + 450.0)
    return out


def _boundaries(cls: list[str], starts: list[np.ndarray], ends: list[np.ndarray],
                names: list[str] | None = None) -> list[np.ndarray]:
    """Formant values at each phone boundary (index i = start of phone i)."""
    n = len(cls)
    names = names or [""] * n
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
                if names[i - 1] in _VELAR:
                    v = _velar_pinch(v, right)
            elif b_cons and not a_cons:
                k = _LOCUS_K.get(b, 0.5)
                v = k * right + (1 - k) * left
                if names[i] in _VELAR:
                    v = _velar_pinch(v, left)
            else:
                v = 0.5 * (left + right)
            if a == "nasal" or b == "nasal":
                v[6] = 360.0  # nasalised transition
        out.append(v)
    out.append(ends[-1])
    return out


_FORMANT_COLS = [kp.F1, kp.F2, kp.F3, kp.B1, kp.B2, kp.B3, kp.FNZ]


def _formants(out: np.ndarray, t: np.ndarray, dur: np.ndarray, pidx: np.ndarray,
              starts: np.ndarray, ends: np.ndarray, bounds: np.ndarray, cls: list[str]) -> None:
    """Steady targets (gliding for diphthongs) plus linear transitions from each boundary."""
    n_ph = len(cls)
    trans = np.array([_TRANS_S.get(c, 0.02) for c in cls])
    after_closure = np.array([i > 0 and c in ("vowel", "diphthong")
                              and cls[i - 1] in ("stop", "nasal", "affricate")
                              for i, c in enumerate(cls)])
    trans[after_closure] = 0.06  # CV transitions from stops/nasals are the long, audible ones
    is_stop = np.array([c == "stop" for c in cls])
    released = np.array([i + 1 < n_ph and cls[i + 1] != "silence" for i in range(n_ph)])
    x = np.clip((t / dur - 0.2) / 0.6, 0.0, 1.0)
    glide = (x * x * (3 - 2 * x))[:, None]
    s, e = starts[pidx], ends[pidx]
    base = s + (e - s) * glide
    tr = np.minimum(trans[pidx], 0.5 * dur)
    safe = np.where(tr > 0, tr, 1.0)
    wl = np.where(tr > 0, np.clip(1.0 - t / safe, 0.0, 1.0), 0.0)[:, None]
    wr = np.where(tr > 0, np.clip(1.0 - (dur - t) / safe, 0.0, 1.0), 0.0)[:, None]
    lb, rb = bounds[:n_ph][pidx], bounds[1:n_ph + 1][pidx]
    vals = base + (lb - s) * wl + (rb - e) * wr
    stop_f = is_stop[pidx]
    # stops hold the locus of the vowel they release into, so the burst (parallel
    # F2..F6) is shaped by the CV locus, e.g. velar bursts sit at the F2/F3 pinch
    # of the following vowel (Stevens 1998 ch. 7); before a pause, the VC locus
    vals[stop_f] = np.where(released[pidx][stop_f, None], rb[stop_f], lb[stop_f])
    out[:, _FORMANT_COLS] = vals


_PAR = (("AF", kp.AF), ("A2", kp.A2), ("A3", kp.A3), ("A4", kp.A4), ("A5", kp.A5),
        ("A6", kp.A6), ("AB", kp.AB))
_SRC_COLS = [kp.AV, kp.AH] + [col for _, col in _PAR]


def _sources(out: np.ndarray, fs: np.ndarray, t: np.ndarray, dur: np.ndarray,
             pidx: np.ndarray, cls: list[str], tg: list[Target | None], ph: tuple,
             sr: int) -> None:
    """Source amplitudes: per-phone closure and burst rows, then masks for bursts,
    aspiration, phrase-final decay and glottal stops."""
    n_ph = len(ph)
    closure = np.zeros((n_ph, len(_SRC_COLS)))  # AV AH AF A2..A6 AB
    burst = np.zeros((n_ph, len(_SRC_COLS)))
    burst_s = np.zeros(n_ph)
    burst_decay = np.zeros(n_ph)
    final_decay = np.zeros(n_ph, dtype=bool)
    asp_until = np.full(n_ph, -1, dtype=np.int64)
    glottal = np.zeros(n_ph, dtype=bool)
    high_f6 = np.zeros(n_ph)
    for i, p in enumerate(ph):
        tgt = tg[i]
        if tgt is None:
            continue
        v, c = tgt.values, cls[i]
        nxt = cls[i + 1] if i + 1 < n_ph else "silence"
        if c in _SONORANT:
            closure[i, 0] = v["AV"] - (3.0 if p.phone.endswith("0") else 0.0)
            final_decay[i] = nxt == "silence" and c in ("vowel", "diphthong")
        elif c == "aspirate":
            closure[i, 1] = v["AH"]
        elif c == "fricative":
            closure[i, 0] = v["AV"]
            closure[i, 2:] = [v[name] for name, _ in _PAR]
            high_f6[i] = _HIGH_F6_HZ.get(p.phone, 0.0)
        elif c in ("stop", "affricate"):
            voiced = info(p.phone).voiced
            burst_s[i] = _BURST_S.get(p.phone, 0.01) if c == "stop" else 0.5
            # a coda stop (end of its word) is released weakly or not at all
            weaker = _CODA_BURST_DB if c == "stop" and _coda(ph, cls, i) else 0.0
            burst[i, 2:] = [max(0.0, v[name] - weaker) if v[name] else 0.0 for name, _ in _PAR]
            if c == "stop" and nxt in ("stop", "affricate"):
                burst[i, 2:] = 0.0  # a stop before another closure is unreleased
            burst[i, 0] = v["AV"]
            if voiced and c == "stop" and i > 0 and cls[i - 1] != "silence":
                closure[i, 0] = _VOICE_BAR_DB  # voice bar during the closure
            if voiced and c == "stop" and nxt in _SONORANT:
                burst[i, 0] = _VOICE_BAR_DB  # short-lag VOT: voicing runs through the release
            if c == "stop":
                burst_decay[i] = _BURST_DECAY_DB
        # a voiceless stop in a syllable onset aspirates into the next phone;
        # codas do not (they are unreleased or glottalised), nor do stops after /s/
        if (c == "stop" and not info(p.phone).voiced and nxt in _SONORANT
                and not _coda(ph, cls, i) and not (i > 0 and ph[i - 1].base == "S")):
            nxt_ph = ph[i + 1]
            vot_s = 0.055 if nxt_ph.phone[-1:] in ("1", "2") else 0.035
            asp_until[i + 1] = nxt_ph.start + min(int(vot_s * sr), nxt_ph.num_samples // 2)
        # vowel-initial word after a pause or a vowel: brief glottal-stop dip
        glottal[i] = (c in ("vowel", "diphthong") and p.word >= 0 and i > 0
                      and ph[i - 1].word != p.word
                      and cls[i - 1] in ("vowel", "diphthong", "silence"))
    bl = np.minimum(burst_s[pidx], np.where(burst_s[pidx] >= 0.5, 0.65, 0.5) * dur)
    in_burst = (burst_s[pidx] > 0) & (t >= dur - bl)
    vals = np.where(in_burst[:, None], burst[pidx], closure[pidx])
    into = np.clip((t - (dur - bl)) / np.maximum(bl, 1e-3), 0.0, 1.0)
    decay = np.where(in_burst, burst_decay[pidx] * into, 0.0)
    vals[:, 2] = np.where(vals[:, 2] > 0, np.maximum(vals[:, 2] - decay, 1.0), 0.0)
    fall = np.clip((t / dur - 0.6) / 0.4, 0.0, 1.0)
    vals[:, 0] -= np.where(final_decay[pidx], 8.0 * fall, 0.0)  # phrase-final decay
    asp = fs < asp_until[pidx]
    vals[asp, 0] = 0.0
    vals[asp, 1] = 58.0
    vals[:, 0] -= np.where(glottal[pidx] & (t < 0.25 * dur), 12.0, 0.0)
    out[:, _SRC_COLS] = vals
    f6 = high_f6[pidx]
    out[:, kp.F6] = np.where(f6 > 0, f6, out[:, kp.F6])
