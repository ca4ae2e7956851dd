"""MouthTrack: node trajectories sampled at ``rate_hz`` on the audio sample clock."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class MouthTrack:
    sample_rate: int
    rate_hz: float
    model: str
    nodes: tuple[str, ...]
    frames: np.ndarray  # (n_frames, n_nodes, 2) float32, mm
    measures: dict[str, np.ndarray]  # name -> (n_frames,) float32: lip_gap, width, jaw (mm)

    @property
    def n_frames(self) -> int:
        return int(self.frames.shape[0])

    def frame_sample(self, k: int) -> int:
        """Frame k stands at sample round(k * sample_rate / rate_hz); frame 0 is sample 0."""
        return round(k * self.sample_rate / self.rate_hz)

    def frame_samples(self) -> np.ndarray:
        return np.round(np.arange(self.n_frames) * (self.sample_rate / self.rate_hz)).astype(
            np.int64)

    def frame_range(self, start_sample: int, end_sample: int) -> tuple[int, int]:
        """Indices [lo, hi) of frames whose sample lies in [start_sample, end_sample)."""
        fs = self.frame_samples()
        lo, hi = np.searchsorted(fs, [start_sample, end_sample])
        return int(lo), int(hi)

    def slice(self, start_sample: int, end_sample: int) -> MouthTrack:
        lo, hi = self.frame_range(start_sample, end_sample)
        return MouthTrack(self.sample_rate, self.rate_hz, self.model, self.nodes,
                          self.frames[lo:hi],
                          {k: v[lo:hi] for k, v in self.measures.items()})

    def to_marks(self) -> dict[str, Any]:
        return {
            "rate_hz": self.rate_hz,
            "model": self.model,
            "nodes": list(self.nodes),
            "frames": np.round(self.frames, 2).tolist(),
            "measures": {k: np.round(v, 3).tolist() for k, v in self.measures.items()},
        }
