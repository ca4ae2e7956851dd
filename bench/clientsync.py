"""Audio/mouth sync from a page's sync probe (client/syncprobe.js).

The probe gives two things on the AudioContext clock:
- the envelope of the audio that really flowed through the graph (an AudioWorklet tap),
  one mean-absolute value per ``block`` context frames from frame ``envStart``;
- every animation frame: the utterance, the context time heard at the frame's time
  (getOutputTimestamp), and the utterance sample the mouth was drawn for.

For each utterance we fetch its audio from the server, build the same envelope, and find
the context time at which its sample 0 was actually heard (normalised cross-correlation
near the page's own estimate, refined to a fraction of a block). The lag of a frame is
then the drawn sample's time minus the time of the audio heard at that frame: positive
means the mouth is ahead of the sound.
"""

from __future__ import annotations

import io
import urllib.request
import wave
from dataclasses import dataclass

import numpy as np

SEARCH_S = 0.15  # how far from the page's own estimate sample 0 may really have played


@dataclass
class SyncResult:
    lags_ms: np.ndarray  # one per drawn frame with audio
    per_utterance: dict[int, float]  # utterance -> median lag (ms)
    matched: dict[int, float]  # utterance -> envelope correlation at the match
    geometry_ms: dict[int, float]  # utterance -> lead of the drawn lip gap (ms), see below

    def summary(self) -> dict[str, float]:
        lag = self.lags_ms
        return {"frames": float(len(lag)), "median_ms": float(np.median(lag)),
                "p95_abs_ms": float(np.percentile(np.abs(lag), 95)),
                "max_abs_ms": float(np.max(np.abs(lag)))}


def fetch_pcm(base_url: str, utterance: int) -> tuple[np.ndarray, int]:
    with urllib.request.urlopen(f"{base_url}/utterances/{utterance}.wav", timeout=10) as r:
        data = r.read()
    with wave.open(io.BytesIO(data)) as w:
        sr = w.getframerate()
        pcm = np.frombuffer(w.readframes(w.getnframes()), dtype="<i2")
    return pcm.astype(np.float64) / 32768.0, sr


def reference_envelope(pcm: np.ndarray, sr: int, block_s: float, n_blocks: int) -> np.ndarray:
    """Mean |x| of the utterance over consecutive windows of block_s seconds from sample 0."""
    edges = np.round(np.arange(n_blocks + 1) * block_s * sr).astype(np.int64)
    edges = np.clip(edges, 0, len(pcm))
    csum = np.concatenate([[0.0], np.cumsum(np.abs(pcm))])
    width = np.maximum(edges[1:] - edges[:-1], 1)
    return (csum[edges[1:]] - csum[edges[:-1]]) / width


def locate(env: np.ndarray, ref: np.ndarray, guess_block: float,
           search_blocks: int) -> tuple[float, float]:
    """Block index (fractional) where ref best matches env near guess, and the correlation."""
    scores = []
    lo = int(round(guess_block)) - search_blocks
    offsets = range(lo, lo + 2 * search_blocks + 1)
    r = ref - ref.mean()
    rn = np.linalg.norm(r) or 1.0
    for off in offsets:
        if off < 0 or off + len(ref) > len(env):
            scores.append(-1.0)
            continue
        seg = env[off:off + len(ref)]
        s = seg - seg.mean()
        scores.append(float(s @ r / ((np.linalg.norm(s) or 1.0) * rn)))
    sc = np.array(scores)
    best = int(np.argmax(sc))
    frac = 0.0
    if 0 < best < len(sc) - 1:  # parabolic refinement
        a, b, c = sc[best - 1], sc[best], sc[best + 1]
        den = a - 2 * b + c
        frac = 0.5 * (a - c) / den if den else 0.0
    return lo + best + frac, float(sc[best])


def fetch_lip_gap(base_url: str, utterance: int) -> tuple[np.ndarray, float]:
    import json

    with urllib.request.urlopen(f"{base_url}/utterances/{utterance}/marks.json", timeout=10) as r:
        mouth = json.loads(r.read())["mouth"]
    return np.asarray(mouth["measures"]["lip_gap"], dtype=np.float64), float(mouth["rate_hz"])


def geometry_lead_ms(heard: np.ndarray, drawn_gap: np.ndarray, track: np.ndarray,
                     track_rate_hz: float, sr: int, search_ms: float = 150.0) -> float:
    """How far ahead of the heard audio the DRAWN lip gap runs, judged by geometry alone.

    The drawn gap (measured from the vertices the renderer drew) is compared with the
    utterance's lip-gap track shifted by each candidate lead; the lead with the highest
    correlation wins. This checks the renderer end to end without trusting the sample
    number it reports.
    """
    frames_at = np.arange(len(track)) * sr / track_rate_hz
    g = drawn_gap - drawn_gap.mean()
    best, best_c = 0.0, -2.0
    for lead in np.arange(-search_ms, search_ms + 0.25, 0.5):
        ref = np.interp(heard + lead / 1000 * sr, frames_at, track)
        r = ref - ref.mean()
        den = (np.linalg.norm(g) * np.linalg.norm(r)) or 1.0
        c = float(g @ r / den)
        if c > best_c:
            best, best_c = float(lead), c
    return best


def analyse(snapshot: dict, base_url: str, min_corr: float = 0.8) -> SyncResult:
    rate, block = snapshot["rate"], snapshot["block"]
    env = np.asarray(snapshot["env"], dtype=np.float64)
    env_t0 = snapshot["envStart"] / rate  # context time of env[0]
    block_s = block / rate
    frames = np.asarray(snapshot["frames"], dtype=np.float64)
    lags, per, matched, geometry = [], {}, {}, {}
    for utt in sorted(set(frames[:, 0].astype(int))):
        f = frames[frames[:, 0] == utt]
        pcm, sr = fetch_pcm(base_url, utt)
        ref = reference_envelope(pcm, sr, block_s, int(len(pcm) / sr / block_s))
        guess_t0 = float(np.median(f[:, 1] - f[:, 2] / sr))  # the page's own belief
        pos, corr = locate(env, ref, (guess_t0 - env_t0) / block_s, int(SEARCH_S / block_s))
        matched[utt] = corr
        if corr < min_corr:
            continue  # the tapped audio does not look like this utterance: don't guess
        t0 = env_t0 + pos * block_s  # context time at which sample 0 was heard
        heard = (f[:, 1] - t0) * sr  # utterance sample heard at each frame's time
        inside = (heard >= 0) & (heard < len(pcm))
        lag = (f[inside, 2] - heard[inside]) / sr * 1000.0
        lags.append(lag)
        per[utt] = float(np.median(lag)) if len(lag) else float("nan")
        track, track_rate = fetch_lip_gap(base_url, utt)
        if inside.sum() > 10:
            geometry[utt] = geometry_lead_ms(heard[inside], f[inside, 3], track, track_rate, sr)
    all_lags = np.concatenate(lags) if lags else np.zeros(0)
    return SyncResult(all_lags, per, matched, geometry)
