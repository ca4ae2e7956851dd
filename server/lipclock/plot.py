"""``lipclock plot``: waveform, phones and mouth trajectories on one time axis.

Modelled on the displacement-over-time figure of the DECface report (Waters &
Levergood 1993): the speech waveform on top, the phone labels under it, then
the mouth measures (``lip_gap``, ``jaw``, ``width``, all mm, derived from the
node mesh) for every mouth model, so the models' lag, overshoot and closure can
be compared against the same audio. matplotlib is an optional extra
(``pip install 'lipclock[plot]'``); without it the command fails with a clear
typed error instead of an ImportError.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .errors import LipclockError

MEASURES = ("lip_gap", "jaw", "width")


class MissingExtraError(LipclockError):
    """An optional dependency (here matplotlib) is not installed."""

    code = "missing_extra"


def plot_utterance(text: str, out_path: str | Path, *, rate_wpm: float | None = None,
                   voice: str | None = None, models: tuple[str, ...] | None = None) -> Path:
    """Synthesize TEXT and write the comparison figure to ``out_path`` (PNG/SVG/PDF)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:  # pragma: no cover - depends on the environment
        raise MissingExtraError(
            "lipclock plot needs matplotlib: pip install 'lipclock[plot]'") from None
    from . import synthesize
    from .face.models import MOUTH_MODELS, mouth_for

    utt = synthesize(text, voice=voice, rate_wpm=rate_wpm)
    tl = utt.timeline
    sr = utt.sample_rate
    chosen = models or tuple(MOUTH_MODELS)
    tracks = {m: mouth_for(tl, m) for m in chosen}

    fig, axes = plt.subplots(2 + len(MEASURES), 1, sharex=True,
                             figsize=(12, 2.0 * (2 + len(MEASURES))),
                             gridspec_kw={"height_ratios": [2, 0.7] + [2] * len(MEASURES)})
    t_s = np.arange(len(utt.samples)) / sr
    axes[0].plot(t_s, utt.samples.astype(np.float32) / 32768.0, lw=0.4, color="0.3")
    axes[0].set_ylabel("waveform")
    axes[0].set_title(text if len(text) < 90 else text[:87] + "...")

    ax = axes[1]
    for i, p in enumerate(tl.phones):
        a, b = p.start / sr, p.end / sr
        ax.axvspan(a, b, color="0.85" if i % 2 else "0.95", lw=0)
        if p.phone != "pau":
            ax.text((a + b) / 2, 0.5, p.phone.rstrip("012"), ha="center", va="center",
                    fontsize=7)
    ax.set_yticks([])
    ax.set_ylabel("phones")

    for ax, name in zip(axes[2:], MEASURES, strict=True):
        for model, tr in tracks.items():
            ax.plot(tr.frame_samples() / sr, tr.measures[name], lw=1.0, label=model)
        ax.set_ylabel(f"{name} (mm)")
        for p in tl.phones:  # mark bilabial closures, where lip_gap must reach 0
            if p.phone.rstrip("012") in ("P", "B", "M"):
                ax.axvspan(p.start / sr, p.end / sr, color="tab:red", alpha=0.08, lw=0)
    axes[2].legend(loc="upper right", fontsize=8, ncol=len(tracks))
    axes[-1].set_xlabel("time (s)  [shaded red: p/b/m]")
    fig.tight_layout()
    out = Path(out_path)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
