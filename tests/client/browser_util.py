"""Helpers shared by the real-browser tests and bench/: the Chromium binary, its flags, and
a real `lipclock serve` process on a free port."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench"))
from serverutil import CHROMIUM, free_port, start_server  # noqa: E402
from serverutil import CHROMIUM_ARGS as ARGS  # noqa: E402

__all__ = ["ARGS", "ARTIFACTS", "CHROMIUM", "FACE_ARTIFACTS", "HAVE_CHROMIUM", "free_port",
           "lip_gaps_while_speaking", "start_server"]
HAVE_CHROMIUM = Path(CHROMIUM).exists()
ARTIFACTS = ROOT / "artifacts" / "screenshots"
FACE_ARTIFACTS = ROOT / "test-artifacts"   # the face's screenshots, for people to look at


def lip_gaps_while_speaking(page, samples: int, every_ms: int) -> list[float]:
    """Once the page's audio clock is past 4000 samples, read the drawn lip gap
    (window.lipclockDebug) `samples` times, `every_ms` apart."""
    page.wait_for_function("window.lipclockDebug.audioSample > 4000", timeout=15000)
    gaps = []
    for _ in range(samples):
        gaps.append(page.evaluate("window.lipclockDebug.lipGap"))
        page.wait_for_timeout(every_ms)
    return gaps
