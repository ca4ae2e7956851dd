"""The browser client in real headless Chromium (Debian's), against a real server process."""

from __future__ import annotations

import pytest
from browser_util import ARTIFACTS, HAVE_CHROMIUM, lip_gaps_while_speaking, start_server

pytestmark = pytest.mark.skipif(not HAVE_CHROMIUM, reason="Debian chromium missing")


def test_page_speaks_and_the_mouth_moves_on_the_audio_clock(server, browser):
    page = browser.new_page(viewport={"width": 1000, "height": 700})
    errors: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(server + "/")
    page.wait_for_function("document.getElementById('status').textContent === 'connected'")
    page.evaluate("""async () => {   // a WebAudio tap: every source passes an analyser
        const c = window.lipclockClient;
        await c.unlock();
        const tap = c.ctx.createAnalyser();
        tap.fftSize = 2048;
        tap.connect(c.ctx.destination);
        c.tap = tap;
        window.peakLevel = 0;
        const buf = new Float32Array(tap.fftSize);
        const watch = () => {
            tap.getFloatTimeDomainData(buf);
            for (const v of buf) window.peakLevel = Math.max(window.peakLevel, Math.abs(v));
            requestAnimationFrame(watch);
        };
        requestAnimationFrame(watch);
    }""")
    page.click("#speak")
    page.wait_for_function("window.lipclockDebug.audioSample > 4000", timeout=15000)
    page.wait_for_function("window.peakLevel > 0.05", timeout=5000)  # real samples flow
    samples = []
    for _ in range(40):
        samples.append(page.evaluate(
            "[window.lipclockDebug.audioSample, window.lipclockDebug.mouthSample,"
            " window.lipclockDebug.lipGap]"))
        page.wait_for_timeout(25)
    audio = [s[0] for s in samples]
    gaps = [s[2] for s in samples]
    assert audio == sorted(audio) and audio[-1] > audio[0]  # the audio clock advances
    assert max(gaps) > 3.0  # the mouth opened while speaking
    # the mouth is drawn for the sample being heard (within one 100 Hz mouth frame)
    assert all(abs(a - m) <= 160 for a, m, _ in samples if a > 0)
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / "speaking.png"))
    assert page.inner_text("#caption").strip()  # captions follow the words
    assert not errors, errors
    page.close()


def test_kiosk_page_loads_clean(server, browser):
    page = browser.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(server + "/kiosk?channel=lobby")
    page.wait_for_timeout(500)
    assert page.evaluate("typeof window.lipclockDebug.audioSample") == "number"
    assert not errors
    page.close()


def test_barge_in_silences_and_closes_the_mouth_within_a_frame(server, browser):
    page = browser.new_page()
    page.goto(server + "/")
    page.wait_for_function("document.getElementById('status').textContent === 'connected'")
    page.fill("#text", "This is a long answer that the user will interrupt. " * 6)
    page.click("#speak")
    page.wait_for_function("window.lipclockDebug.audioSample > 8000", timeout=15000)
    page.evaluate("""() => {
        // count the frames drawn after the stop message until one shows a closed, silent
        // mouth: counting frames, not milliseconds, keeps a busy machine from mattering
        window.stopSeen = false; window.framesAfterStop = 0; window.closedFrame = null;
        const c = window.lipclockClient;
        c.addEventListener('stop', () => { window.stopSeen = true; });
        c.addEventListener('frame', (e) => {
            if (!window.stopSeen || window.closedFrame !== null) return;
            window.framesAfterStop++;
            if (e.detail.lipGap === 0 && e.detail.audioSample === 0)
                window.closedFrame = window.framesAfterStop;
        });
    }""")
    page.click("#stop")
    page.wait_for_function("window.closedFrame !== null", timeout=5000)
    assert page.evaluate("window.closedFrame") == 1  # the first frame drawn after the stop
    page.close()


def test_device_clock_mode_draws_the_mouth_from_the_servers_clock(device_server, browser):
    page = browser.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(device_server + "/")
    page.wait_for_function("document.getElementById('status').textContent"
                           " === 'connected (device clock)'")
    assert page.is_hidden("#unlock")  # the server plays the sound: no prompt
    page.click("#speak")
    gaps = lip_gaps_while_speaking(page, 30, 30)
    assert max(gaps) > 3.0
    assert not errors, errors
    page.close()


BLOCKING_AUDIO = """
// Headless Chromium does not enforce the autoplay policy, so emulate a browser that does:
// the context stays suspended, and resume() never settles, until there is a user gesture.
const Real = window.AudioContext;
window.AudioContext = class extends Real {
  constructor(...a) { super(...a); this._blocked = true; }
  get state() { return this._blocked ? "suspended" : super.state; }
  resume() {
    if (navigator.userActivation && navigator.userActivation.isActive) {
      this._blocked = false;
      return super.resume();
    }
    return new Promise(() => {});
  }
};
"""


def test_blocked_autoplay_shows_a_tap_to_enable_prompt(server, browser):
    page = browser.new_page()
    page.add_init_script(BLOCKING_AUDIO)
    page.goto(server + "/")
    page.wait_for_function("document.getElementById('status').textContent === 'connected'")
    page.wait_for_function("document.getElementById('unlock').hidden === false", timeout=5000)
    assert "enable sound" in page.inner_text("#unlock").lower()
    page.click("#unlock")  # a real gesture unlocks audio
    page.wait_for_function("document.getElementById('unlock').hidden === true", timeout=5000)
    page.close()


def test_server_going_away_mid_utterance_closes_the_mouth_and_reconnects(browser):
    url, proc = start_server()
    page = browser.new_page()
    try:
        page.goto(url + "/")
        page.wait_for_function("document.getElementById('status').textContent === 'connected'")
        page.fill("#text", "The server will vanish in the middle of this long sentence. " * 4)
        page.click("#speak")
        page.wait_for_function("window.lipclockDebug.audioSample > 4000", timeout=15000)
        proc.kill()
        proc.wait(timeout=10)
        page.wait_for_function("window.lipclockDebug.audioSample === 0 &&"
                               " window.lipclockDebug.lipGap === 0", timeout=5000)
        page.wait_for_function("document.getElementById('status').textContent"
                               ".startsWith('reconnecting')", timeout=5000)
        url, proc = start_server(port=int(url.rsplit(":", 1)[1]))
        page.wait_for_function("document.getElementById('status').textContent === 'connected'",
                               timeout=20000)
    finally:
        page.close()
        proc.terminate()
        proc.wait(timeout=10)
