"""Parameter tracks: Timeline -> one Klatt parameter frame every 5 ms.

Per-phone targets come from ``data/klatt_targets.tsv`` (read by targets.py).
The rules that make them speech (after Klatt 1980 and the Holmes-Mattingly-Shearme
boundary scheme used by rule synthesizers):

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

import numpy as np

from . import klatt_params as kp
from .phoneset import PAUSE, info, phones, written_forms
from .targets import FORMANT_FIELDS_N, target_for
from .timeline import Timeline
from .voices import Voice

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


# Phone classes as small integer codes, so that each rule below is an array mask.
_CLASSES = ("silence", "vowel", "diphthong", "stop", "affricate", "fricative", "nasal", "liquid",
            "glide", "aspirate")
_CODE = {c: i for i, c in enumerate(_CLASSES)}
_SILENCE, _STOP, _NASAL = _CODE["silence"], _CODE["stop"], _CODE["nasal"]


def _class_set(*names: str) -> np.ndarray:
    """Membership table by class code: ``_class_set("vowel", "diphthong")[cls]`` is a mask."""
    table = np.zeros(len(_CLASSES), dtype=bool)
    table[[_CODE[c] for c in names]] = True
    return table


def _class_values(values: dict[str, float], default: float) -> np.ndarray:
    """Per-class constants (``_LOCUS_K``, ``_TRANS_S``) as a table by class code."""
    return np.array([values.get(c, default) for c in _CLASSES])


_VOCALIC = _class_set("vowel", "diphthong")
_SONORANTS = _class_set(*_SONORANT)
_CLOSURES = _class_set("stop", "affricate")
# what keeps a stop in its syllable's onset: a vowel or an approximant after it
_NUCLEUS = _class_set("vowel", "diphthong", "liquid", "glide")
_CLOSED = _class_set("stop", "nasal", "affricate")
_LOCUS_K_BY_CLASS = _class_values(_LOCUS_K, 0.5)
_TRANS_S_BY_CLASS = _class_values(_TRANS_S, 0.02)
_VELAR = frozenset({"K", "G", "NG"})
_NO_FORMANTS = np.array([500.0, 1500.0, 2500.0, 80.0, 100.0, 150.0, 270.0])  # all-pause input


_PAR = (("AF", kp.AF), ("A2", kp.A2), ("A3", kp.A3), ("A4", kp.A4), ("A5", kp.A5),
        ("A6", kp.A6), ("AB", kp.AB))
_SRC_COLS = [kp.AV, kp.AH] + [col for _, col in _PAR]


@dataclass(frozen=True, slots=True)
class _PhoneRows:
    """Everything the rules need to know about a phone string ("AH0", "K", "pau") that
    does not depend on its neighbours, one row per phone string."""
    index: dict[str, int]  # phone string -> row
    cls: np.ndarray  # class code
    voiced: np.ndarray
    stressed: np.ndarray  # stress 1 or 2
    is_pause: np.ndarray
    is_hh: np.ndarray
    is_s: np.ndarray
    velar: np.ndarray
    start: np.ndarray  # (rows, 7) F1 F2 F3 B1 B2 B3 FNZ (unstressed vowels reduced)
    end: np.ndarray
    av: np.ndarray
    par: np.ndarray  # (rows, 7) AF A2..A6 AB
    closure: np.ndarray  # (rows, 9) AV AH AF A2..A6 AB outside any burst
    burst_s: np.ndarray  # release burst length (0: no burst)
    high_f6: np.ndarray  # F6 pole moved up for the noise of /s z/ (0: default)


@cache
def _phone_rows() -> _PhoneRows:
    names = [PAUSE] + [s for name in phones() if name != PAUSE for s in written_forms(name)]
    n = len(names)
    rows = {"cls": np.zeros(n, dtype=np.int64), "start": np.zeros((n, FORMANT_FIELDS_N)),
            "end": np.zeros((n, FORMANT_FIELDS_N)), "av": np.zeros(n),
            "par": np.zeros((n, len(_PAR))),
            "closure": np.zeros((n, len(_SRC_COLS))), "burst_s": np.zeros(n),
            "high_f6": np.zeros(n)}
    flags = {f: np.zeros(n, dtype=bool)
             for f in ("voiced", "stressed", "is_pause", "is_hh", "is_s", "velar")}
    for i, phone in enumerate(names):
        inf = info(phone)
        c = inf.cls
        rows["cls"][i] = _CODE[c]
        flags["voiced"][i] = inf.voiced
        flags["stressed"][i] = phone[-1:] in ("1", "2")
        flags["is_pause"][i] = phone == PAUSE
        flags["is_hh"][i] = inf.name == "HH"
        flags["is_s"][i] = inf.name == "S"
        flags["velar"][i] = inf.name in _VELAR
        if phone == PAUSE:
            continue
        tgt = target_for(phone)
        v = tgt.values
        rows["start"][i], rows["end"][i] = tgt.start, tgt.end
        rows["av"][i] = v["AV"]
        rows["par"][i] = [v[name] for name, _ in _PAR]
        closure = rows["closure"][i]
        if c in _SONORANT:  # voiced; unstressed vowels 3 dB weaker
            closure[0] = v["AV"] - (3.0 if phone.endswith("0") else 0.0)
        elif c == "aspirate":
            closure[1] = v["AH"]
        elif c == "fricative":  # noise shaped by place
            closure[0] = v["AV"]
            closure[2:] = rows["par"][i]
            rows["high_f6"][i] = _HIGH_F6_HZ.get(phone, 0.0)
        elif c == "stop":
            rows["burst_s"][i] = _BURST_S.get(phone, 0.01)
        elif c == "affricate":
            rows["burst_s"][i] = 0.5  # the frication of an affricate is its "burst"
    return _PhoneRows(index={p: i for i, p in enumerate(names)}, **rows, **flags)


@dataclass(frozen=True, slots=True)
class _Phones:
    """The utterance's phones as arrays (row into _PhoneRows, class, neighbours' classes)."""
    row: np.ndarray
    cls: np.ndarray
    prev: np.ndarray  # class of the phone before (silence before the first)
    next: np.ndarray  # class of the phone after (silence after the last)
    start: np.ndarray  # samples
    end: np.ndarray
    word: np.ndarray

    @staticmethod
    def of(ph: tuple) -> _Phones:
        rows = _phone_rows()
        row = np.array([rows.index[p.phone] for p in ph], dtype=np.int64)
        cls = rows.cls[row]
        return _Phones(row, cls, _shift_right(cls, _SILENCE), _shift_left(cls, _SILENCE),
                       np.array([p.start for p in ph], dtype=np.int64),
                       np.array([p.end for p in ph], dtype=np.int64),
                       np.array([p.word for p in ph], dtype=np.int64))


def _shift_right(a: np.ndarray, fill: object) -> np.ndarray:
    """a[i - 1] at i (fill at 0): the previous phone's value."""
    return np.concatenate([np.full(1, fill, dtype=a.dtype), a[:-1]])


def _shift_left(a: np.ndarray, fill: object) -> np.ndarray:
    """a[i + 1] at i (fill at the end): the next phone's value."""
    return np.concatenate([a[1:], np.full(1, fill, dtype=a.dtype)])


def _next_where(mask: np.ndarray) -> np.ndarray:
    """For each i the first j > i with mask[j], or len(mask) if there is none."""
    n = len(mask)
    at = np.where(mask, np.arange(n), n)
    return _shift_left(np.minimum.accumulate(at[::-1])[::-1], n)


def _prev_where(mask: np.ndarray) -> np.ndarray:
    """For each i the last j < i with mask[j], or -1 if there is none."""
    at = np.where(mask, np.arange(len(mask)), -1)
    return _shift_right(np.maximum.accumulate(at), -1)


def _coda(u: _Phones) -> np.ndarray:
    """Phone ends its word's syllable: a pause, another word or a consonant follows."""
    return ~_NUCLEUS[u.next]


def klatt_frames(timeline: Timeline, voice: Voice) -> np.ndarray:
    """Frames (n, N_PARAMS) float32 covering the timeline; see klatt_params for columns.

    Per-phone quantities are built once, then spread over frames by each frame's
    phone index, so the cost is a few numpy operations per utterance.
    """
    sr = timeline.sample_rate
    n = kp.n_frames_for(timeline.num_samples, sr)
    fs = np.round(np.arange(n) * (sr / kp.FRAME_RATE_HZ)).astype(np.int64)
    # One float32 row per parameter track, transposed to frames at the end. The
    # rules compute in float64 and each track is rounded once, as it is stored.
    fixed = np.zeros(kp.N_PARAMS)
    for col, v in _DEFAULTS.items():
        fixed[col] = v
    fixed[kp.OQ] = voice.open_quotient
    fixed[kp.TL] = voice.tilt_db
    out = np.empty((kp.N_PARAMS, n), dtype=np.float32)
    out[:] = fixed[:, None]
    out[kp.F0] = timeline.f0_at(fs)
    ph = timeline.phones
    if not ph:
        return np.ascontiguousarray(out.T)
    u = _Phones.of(ph)
    starts, ends = _steady(u)
    bounds = _boundaries(u, starts, ends)
    n_ph = len(ph)
    pidx = np.clip(np.searchsorted(u.end, fs, side="right"), 0, n_ph - 1)
    t = (fs - u.start[pidx]) / sr
    dur = np.maximum((u.end - u.start) / sr, 1e-3)[pidx]
    formants = _formants(t, dur, pidx, starts, ends, bounds, u)
    # The synthesizer scales F1..F6 by the voice's tract length but not the nasal
    # pair. The murmur's zero exists to cancel F1 (Klatt 1980), so where it is in
    # use (not parked on the pole) it must move with the scaled F1.
    nz = formants[_FORMANT_COLS.index(kp.FNZ)]
    nz[:] = np.where(np.abs(nz - _DEFAULTS[kp.FNP]) > 1.0, nz * voice.formant_scale, nz)
    out[_FORMANT_COLS] = formants
    amps, f6 = _sources(fs, t, dur, pidx, u, sr)
    out[kp.F6] = f6
    # smooth voicing onsets/offsets only (never AF/AH/A*: keeps bursts sharp)
    av = amps[0].copy()
    amps[0, 1:-1] = 0.25 * av[:-2] + 0.5 * av[1:-1] + 0.25 * av[2:]
    out[_SRC_COLS] = amps
    return np.ascontiguousarray(out.T)


def _steady(u: _Phones) -> tuple[np.ndarray, np.ndarray]:
    """Start/end formant vectors (n, 7) of each phone."""
    rows = _phone_rows()
    starts, ends = rows.start[u.row], rows.end[u.row]
    n = len(u.row)
    # HH takes the formants of the vowel or approximant that follows it
    hh = np.flatnonzero(rows.is_hh[u.row])
    src = _next_where(_NUCLEUS[u.cls])[hh]
    hh, src = hh[src < n], src[src < n]
    starts[hh] = ends[hh] = starts[src]
    # pauses borrow their neighbours' (the next phone's start, else the previous
    # phone's end) so nothing moves in silence
    pause = rows.is_pause[u.row]
    if pause.any():
        nxt, prv = _next_where(~pause), _prev_where(~pause)
        fwd = pause & (nxt < n)
        back = pause & ~fwd & (prv >= 0)
        starts[fwd] = ends[fwd] = starts[nxt[fwd]]
        starts[back] = ends[back] = ends[prv[back]]
        lone = pause & ~fwd & ~back
        starts[lone] = ends[lone] = _NO_FORMANTS
    return starts, ends


def _velar_pinch(v: np.ndarray, vowel: np.ndarray) -> np.ndarray:
    """Velar loci follow the vowel: F2 starts just above the vowel's F2 and F3 comes down
    to meet it (the 'velar pinch', Stevens 1998 ch. 7). One boundary per row."""
    out = v.copy()
    f2 = np.clip(vowel[:, 1] * 1.08 + 120.0, 1300.0, 2400.0)
    out[:, 1] = f2
    out[:, 2] = np.minimum(vowel[:, 2], f2 + 450.0)
    return out


def _locus_mix(k: np.ndarray, cons: np.ndarray, vowel: np.ndarray) -> np.ndarray:
    """``k * consonant + (1 - k) * vowel`` row by row."""
    k = k[:, None]
    return k * cons + (1 - k) * vowel


def _boundaries(u: _Phones, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Formant values (n + 1, 7) at each phone boundary (row i = start of phone i)."""
    a, b = u.cls[:-1], u.cls[1:]  # the phones left and right of each inner boundary
    left, right = ends[:-1], starts[1:]
    velar = _phone_rows().velar[u.row]
    # between two consonants or two vowels: halfway
    v = 0.5 * (left + right)
    # consonant-vowel: the consonant's locus pulls the vowel's formants toward it
    cv = np.flatnonzero(~_VOCALIC[a] & _VOCALIC[b])
    v[cv] = _locus_mix(_LOCUS_K_BY_CLASS[a[cv]], left[cv], right[cv])
    pinch = cv[velar[:-1][cv]]
    v[pinch] = _velar_pinch(v[pinch], right[pinch])
    # vowel-consonant: the same, mirrored
    vc = np.flatnonzero(_VOCALIC[a] & ~_VOCALIC[b])
    v[vc] = _locus_mix(_LOCUS_K_BY_CLASS[b[vc]], right[vc], left[vc])
    pinch = vc[velar[1:][vc]]
    v[pinch] = _velar_pinch(v[pinch], left[pinch])
    v[(a == _NASAL) | (b == _NASAL), 6] = 360.0  # nasalised transition
    # at a pause nothing moves: the boundary is the speaking side's own value
    v[b == _SILENCE] = left[b == _SILENCE]
    v[a == _SILENCE] = right[a == _SILENCE]
    return np.concatenate([starts[:1], v, ends[-1:]])


_FORMANT_COLS = [kp.F1, kp.F2, kp.F3, kp.B1, kp.B2, kp.B3, kp.FNZ]


def _formants(t: np.ndarray, dur: np.ndarray, pidx: np.ndarray, starts: np.ndarray,
              ends: np.ndarray, bounds: np.ndarray, u: _Phones) -> np.ndarray:
    """Tracks (7, n_frames) of F1 F2 F3 B1 B2 B3 FNZ: steady targets (gliding for
    diphthongs) plus linear transitions from each boundary."""
    cls = u.cls
    trans = _TRANS_S_BY_CLASS[cls]
    # CV transitions from stops/nasals are the long, audible ones
    trans[_VOCALIC[cls] & _CLOSED[u.prev]] = 0.06
    tr = np.minimum(trans[pidx], 0.5 * dur)
    safe = np.where(tr > 0, tr, 1.0)
    wl = np.where(tr > 0, np.clip(1.0 - t / safe, 0.0, 1.0), 0.0)
    wr = np.where(tr > 0, np.clip(1.0 - (dur - t) / safe, 0.0, 1.0), 0.0)
    # Each frame is its phone's target plus whichever of the terms below are not
    # zero (formants are positive, so adding a zero term changes no bit).
    # Rows F1 F2 F3 B1 B2 B3 FNZ, one column per phone (bounds: per boundary).
    starts, ends, bounds = (np.ascontiguousarray(a.T) for a in (starts, ends, bounds))
    vals = np.take(starts, pidx, axis=1)
    # diphthongs glide from the first target to the second in the middle of the vowel
    gl = np.flatnonzero(np.any(ends != starts, axis=0)[pidx])
    x = np.clip((t[gl] / dur[gl] - 0.2) / 0.6, 0.0, 1.0)
    _add_term(vals, gl, ends - starts, pidx, x * x * (3 - 2 * x))
    # transitions: from the boundary value at the start, toward the one at the end
    fl = np.flatnonzero(wl > 0)
    _add_term(vals, fl, bounds[:, :-1] - starts, pidx, wl[fl])
    fr = np.flatnonzero(wr > 0)
    _add_term(vals, fr, bounds[:, 1:] - ends, pidx, wr[fr])
    # stops hold the locus of the vowel they release into, so the burst (parallel
    # F2..F6) is shaped by the CV locus, e.g. velar bursts sit at the F2/F3 pinch
    # of the following vowel (Stevens 1998 ch. 7); before a pause, the VC locus
    released = u.next != _SILENCE
    hold = np.where(released, bounds[:, 1:], bounds[:, :-1])
    stop_f = np.flatnonzero((cls == _STOP)[pidx])
    vals[:, stop_f] = hold[:, pidx[stop_f]]
    return vals


def _add_term(vals: np.ndarray, frames: np.ndarray, per_phone: np.ndarray, pidx: np.ndarray,
              weight: np.ndarray) -> None:
    """``vals[:, frames] += per_phone[:, pidx[frames]] * weight``, one row at a time
    (1-D indexing is several times faster than the 2-D form)."""
    at = pidx[frames]
    for track, term in zip(vals, per_phone, strict=True):
        track[frames] += term[at] * weight


def _sources(fs: np.ndarray, t: np.ndarray, dur: np.ndarray, pidx: np.ndarray, u: _Phones,
             sr: int) -> tuple[np.ndarray, np.ndarray]:
    """Source amplitude tracks (9, n_frames) of AV AH AF A2..A6 AB, and the F6 track.

    Per-phone closure and burst rows, then masks for bursts, aspiration,
    phrase-final decay and glottal stops."""
    rows = _phone_rows()
    n_ph = len(u.row)
    cls, nxt, prv = u.cls, u.next, u.prev
    stop = cls == _STOP
    voiced = rows.voiced[u.row]
    # sonorants voice, /h/ aspirates, fricatives are noise shaped by place (_phone_rows);
    # stops and affricates are silent closures, except for a voice bar
    closure = rows.closure[u.row]  # AV AH AF A2..A6 AB
    closure[stop & voiced & (prv != _SILENCE), 0] = _VOICE_BAR_DB
    # the release burst (used by stops and affricates only): the phone's own noise
    # amplitudes; a coda stop (end of its word) is released weakly or not at all
    burst = np.zeros((n_ph, len(_SRC_COLS)))
    weaker = np.where(stop & _coda(u), _CODA_BURST_DB, 0.0)[:, None]
    par = rows.par[u.row]
    burst[:, 2:] = np.where(par != 0, np.maximum(0.0, par - weaker), 0.0)
    burst[stop & _CLOSURES[nxt], 2:] = 0.0  # a stop before another closure is unreleased
    burst[:, 0] = rows.av[u.row]
    # short-lag VOT: voicing runs through a voiced stop's release
    burst[stop & voiced & _SONORANTS[nxt], 0] = _VOICE_BAR_DB
    burst_s = rows.burst_s[u.row]
    burst_decay = np.where(stop, _BURST_DECAY_DB, 0.0)
    final_decay = _VOCALIC[cls] & (nxt == _SILENCE)
    # a voiceless stop in a syllable onset aspirates into the next phone;
    # codas do not (they are unreleased or glottalised), nor do stops after /s/
    after_s = _shift_right(rows.is_s[u.row], False)
    into = np.flatnonzero(stop & ~voiced & _SONORANTS[nxt] & ~_coda(u) & ~after_s) + 1
    vot = np.where(rows.stressed[u.row[into]], int(0.055 * sr), int(0.035 * sr))
    asp_until = np.full(n_ph, -1, dtype=np.int64)
    asp_until[into] = u.start[into] + np.minimum(vot, (u.end[into] - u.start[into]) // 2)
    # vowel-initial word after a pause or a vowel: brief glottal-stop dip
    glottal = (_VOCALIC[cls] & (u.word >= 0) & (_shift_right(u.word, -1) != u.word)
               & _class_set("vowel", "diphthong", "silence")[prv])
    glottal[0] = False
    # rows AV AH AF A2..A6 AB, one column per frame
    vals = np.take(closure.T, pidx, axis=1)
    # the burst takes the end of the phone; the transient decays over it
    bf = np.flatnonzero(burst_s[pidx] > 0)  # frames of stops and affricates
    bs, bd = burst_s[pidx[bf]], dur[bf]
    bl = np.minimum(bs, np.where(bs >= 0.5, 0.65, 0.5) * bd)
    in_burst = t[bf] >= bd - bl
    bf, bl, bd = bf[in_burst], bl[in_burst], bd[in_burst]
    vals[:, bf] = burst.T[:, pidx[bf]]
    into_burst = np.clip((t[bf] - (bd - bl)) / np.maximum(bl, 1e-3), 0.0, 1.0)
    af = vals[2].copy()
    af[bf] -= burst_decay[pidx[bf]] * into_burst
    vals[2] = np.where(vals[2] > 0, np.maximum(af, 1.0), 0.0)
    fall = np.clip((t / dur - 0.6) / 0.4, 0.0, 1.0)
    vals[0] -= np.where(final_decay[pidx], 8.0 * fall, 0.0)  # phrase-final decay
    asp = fs < asp_until[pidx]
    vals[0, asp] = 0.0
    vals[1, asp] = 58.0
    vals[0] -= np.where(glottal[pidx] & (t < 0.25 * dur), 12.0, 0.0)
    f6 = rows.high_f6[u.row][pidx]
    return vals, np.where(f6 > 0, f6, _DEFAULTS[kp.F6])
