"""The page's sync probe, timeline strip and spring sliders, in real headless Chromium.

The sync figures themselves (|median| <= 5 ms, p95 <= 20 ms, with and without a jitter
proxy) come from bench/bench_client_sync.py. Here we check that the probe and the analysis
work at all and that the drawn mouth is on the heard audio to within one 60 Hz frame: a
mouth drawn from the wrong clock (the send time, the schedule time without output
latency, a stale sample) is off by tens to hundreds of milliseconds.
"""

from __future__ import annotations

import json
import sys
import urllib.request
from pathlib import Path

import numpy as np
import pytest
from browser_util import HAVE_CHROMIUM

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from bench_client_sync import measure  # noqa: E402
from clientsync import analyse  # noqa: E402

pytestmark = pytest.mark.skipif(not HAVE_CHROMIUM, reason="Debian chromium missing")
FRAME_MS = 1000 / 60


def test_drawn_mouth_follows_the_tapped_audio_within_a_frame(server, browser):
    snap = measure(browser, server, ["Bob bought a big map of Boston, and Peter packed paper."])
    res = analyse(snap, server)
    assert res.matched and min(res.matched.values()) > 0.8, res.matched  # the tap heard it
    assert len(res.lags_ms) > 30
    s = res.summary()
    assert abs(s["median_ms"]) < FRAME_MS, s
    # the drawn lip gap (measured on the mesh) is the stream's, not shifted in time
    assert all(abs(g) <= 20 for g in res.geometry_ms.values()), res.geometry_ms
    assert snap["stats"]["lateChunks"] == 0


def _open(server, browser):
    page = browser.new_page(viewport={"width": 1000, "height": 700})
    errors: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    sent: list[dict] = []

    def on_ws(ws):
        ws.on("framesent", lambda payload: sent.append(json.loads(payload))
              if isinstance(payload, str) else None)

    page.on("websocket", on_ws)
    page.goto(server + "/")
    page.wait_for_function("document.getElementById('status').textContent === 'connected'")
    page.wait_for_function("document.getElementById('model').options.length > 0")
    return page, errors, sent


def _speak_and_wait(page):
    page.evaluate("""() => new Promise((resolve) => {
        const c = window.lipclockClient;
        const done = () => { c.removeEventListener('utterance-end', done); resolve(); };
        c.addEventListener('utterance-end', done);
        document.getElementById('speak').click();
    })""")


def test_spring_sliders_send_scaled_constants_only_for_the_spring_model(server, browser):
    defaults = json.load(urllib.request.urlopen(server + "/voices"))["spring_params"]
    page, errors, sent = _open(server, browser)
    page.fill("#text", "Map.")
    page.select_option("#model", "spring")
    page.fill("#stiffness", "1")   # log2 scale: x2
    page.fill("#damping", "-1")    # x0.5
    _speak_and_wait(page)
    speak = [m for m in sent if m.get("type") == "speak"][-1]
    params = speak["spring_params"]
    assert params["lips.stiffness"] == pytest.approx(2 * defaults["lips.stiffness"])
    assert params["jaw.damping"] == pytest.approx(0.5 * defaults["jaw.damping"])
    assert "skull.stiffness" not in params and "lips.mass" not in params
    assert page.inner_text("#stiffnessOut") == "×2.00"

    page.select_option("#model", "linear")
    assert page.eval_on_selector("#springs", "f => f.disabled")
    _speak_and_wait(page)
    speak = [m for m in sent if m.get("type") == "speak"][-1]
    assert speak["mouth_model"] == "linear" and "spring_params" not in speak
    assert not errors, errors
    page.close()


def test_timeline_strip_shows_the_utterance_under_a_playhead(server, browser):
    page, errors, _ = _open(server, browser)
    page.fill("#text", "The quick brown fox jumps over the lazy dog.")
    before = page.locator("#timeline").screenshot()
    _speak_and_wait(page)
    after = page.locator("#timeline").screenshot()
    # the strip held the last position: phone labels, viseme boxes and the lip-gap trace
    from io import BytesIO

    from PIL import Image
    a = np.asarray(Image.open(BytesIO(before)).convert("RGB"), dtype=int)
    b = np.asarray(Image.open(BytesIO(after)).convert("RGB"), dtype=int)
    assert len(np.unique(a.reshape(-1, 3), axis=0)) <= 2          # empty strip before
    changed = np.abs(a - b).sum(axis=2) > 30
    assert changed.mean() > 0.02, changed.mean()
    gap_red = (b[..., 0] > 200) & (b[..., 1] < 140) & (b[..., 2] < 140)  # the #ff6b6b trace
    assert gap_red.sum() > 50
    assert not errors, errors
    page.close()
