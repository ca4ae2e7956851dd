"""Mouth data in the formats people already use (tables in ``viseme_tables/exports.tsv``).

* ``oculus``: the 15 Oculus/OpenXR visemes as weight frames at 100 Hz.
* ``azure``: Azure Speech viseme events ``{VisemeId, AudioOffset}``, offsets in 100 ns ticks.
* ``arkit``: ARKit blendshape weights at 60 fps from the mouth measures.
* ``rhubarb-json`` / ``rhubarb-tsv``: Rhubarb Lip Sync mouth cues A-H and X.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import TableError, UnknownChoiceError
from ..speech.phoneset import phones
from ..speech.timeline import Timeline
from ..tables import iter_tsv, package_file
from .track import MouthTrack

EXPORT_FORMATS = ("oculus", "azure", "arkit", "rhubarb-json", "rhubarb-tsv")
OCULUS = ("sil", "PP", "FF", "TH", "DD", "kk", "CH", "SS", "nn", "RR", "aa", "E", "ih", "oh",
          "ou")
RHUBARB = ("A", "B", "C", "D", "E", "F", "G", "H", "X")
ARKIT = ("jawOpen", "mouthClose", "mouthFunnel", "mouthPucker", "mouthSmileLeft",
         "mouthSmileRight", "mouthStretchLeft", "mouthStretchRight", "mouthPressLeft",
         "mouthPressRight")


def load_export_map(path: Path) -> dict[str, tuple[str, int, str]]:
    out: dict[str, tuple[str, int, str]] = {}
    for line, f in iter_tsv(path):
        if len(f) != 4:
            raise TableError(path, line, f"expected 4 columns, got {len(f)}")
        ph, oc, az, rb = f
        if ph not in phones():
            raise TableError(path, line, f"unknown phone {ph!r}")
        if oc not in OCULUS:
            raise TableError(path, line, f"unknown Oculus viseme {oc!r}")
        if not az.isdigit() or not 0 <= int(az) <= 21:
            raise TableError(path, line, f"Azure viseme id must be 0-21, got {az!r}")
        if rb not in RHUBARB:
            raise TableError(path, line, f"unknown Rhubarb shape {rb!r}")
        out[ph] = (oc, int(az), rb)
    missing = sorted(set(phones()) - set(out))
    if missing:
        raise TableError(path, 1, f"phones without an export mapping: {' '.join(missing)}")
    return out


@cache
def export_map() -> dict[str, tuple[str, int, str]]:
    return load_export_map(package_file("lipclock.viseme_tables", "exports.tsv"))


def export(fmt: str, timeline: Timeline, visemes: Any, mouth: MouthTrack) -> Any:
    if fmt not in EXPORT_FORMATS:
        raise UnknownChoiceError("export format", fmt, EXPORT_FORMATS)
    if fmt == "oculus":
        return oculus(timeline, mouth)
    if fmt == "azure":
        return azure(timeline)
    if fmt == "arkit":
        return arkit(mouth)
    cues = rhubarb_cues(timeline)
    if fmt == "rhubarb-json":
        return {"metadata": {"duration": round(timeline.duration_s, 3)}, "mouthCues": cues}
    return "".join(f"{c['start']:.2f}\t{c['value']}\n" for c in cues) + \
        f"{timeline.duration_s:.2f}\tX\n"


def _segments(timeline: Timeline, column: int) -> list[tuple[Any, int, int]]:
    """Merge adjacent phones with the same mapped value: (value, start, end)."""
    m = export_map()
    out: list[tuple[Any, int, int]] = []
    for p in timeline.phones:
        v = m[p.base][column]
        if out and out[-1][0] == v:
            out[-1] = (v, out[-1][1], p.end)
        else:
            out.append((v, p.start, p.end))
    return out


def azure(timeline: Timeline) -> list[dict[str, int]]:
    """Azure-style viseme events: AudioOffset in 100-nanosecond ticks from the audio start."""
    sr = timeline.sample_rate
    return [{"VisemeId": v, "AudioOffset": round(a * 10_000_000 / sr)}
            for v, a, _ in _segments(timeline, 1)]


def rhubarb_cues(timeline: Timeline) -> list[dict[str, Any]]:
    sr = timeline.sample_rate
    return [{"start": round(a / sr, 3), "end": round(b / sr, 3), "value": v}
            for v, a, b in _segments(timeline, 2)]


def oculus(timeline: Timeline, mouth: MouthTrack) -> dict[str, Any]:
    """Per mouth frame, one weight per Oculus viseme (cross-fading over 40 ms at changes)."""
    m = export_map()
    fs = mouth.frame_samples()
    ends = np.array([p.end for p in timeline.phones])
    idx = np.clip(np.searchsorted(ends, fs, side="right"), 0, len(ends) - 1)
    cols = np.array([OCULUS.index(m[timeline.phones[i].base][0]) for i in range(len(ends))])
    weights = np.zeros((len(fs), len(OCULUS)), dtype=np.float32)
    weights[np.arange(len(fs)), cols[idx]] = 1.0
    k = max(1, round(0.04 * mouth.rate_hz))
    kernel = np.ones(k) / k
    smoothed = np.stack([np.convolve(weights[:, j], kernel, mode="same")
                         for j in range(len(OCULUS))], axis=1)
    smoothed /= np.maximum(smoothed.sum(axis=1, keepdims=True), 1e-9)  # weights sum to 1
    return {"rate_hz": mouth.rate_hz, "visemes": list(OCULUS),
            "frames": np.round(smoothed, 3).tolist()}


def arkit(mouth: MouthTrack, fps: float = 60.0) -> dict[str, Any]:
    """ARKit blendshape weights (0..1) resampled to ``fps`` from the mouth measures (mm)."""
    n_out = int(mouth.n_frames * fps / mouth.rate_hz)
    t = np.arange(n_out) / fps
    src_t = np.arange(mouth.n_frames) / mouth.rate_hz

    def res(v: np.ndarray) -> np.ndarray:
        return np.interp(t, src_t, v)

    gap, width, jaw = (res(mouth.measures[k]) for k in ("lip_gap", "width", "jaw"))
    jaw_open = np.clip(jaw / 16.0, 0, 1)
    close = np.clip(1.0 - gap / 3.0, 0, 1) * np.clip(jaw / 4.0, 0, 1)  # lips shut, jaw open
    narrow = np.clip((50.0 - width) / 14.0, 0, 1)
    smile = np.clip((width - 54.0) / 8.0, 0, 1)
    funnel = narrow * np.clip(gap / 8.0, 0, 1)
    pucker = narrow * np.clip(1.0 - gap / 8.0, 0, 1)
    press = np.clip(1.0 - gap / 1.0, 0, 1) * (jaw < 4.0)
    cols = [jaw_open, close, funnel, pucker, smile, smile, smile * 0.5, smile * 0.5, press, press]
    frames = np.round(np.stack(cols, axis=1), 3)
    return {"fps": fps, "blendshapes": list(ARKIT), "frames": frames.tolist()}
