"""The browser client in real headless Chromium (Debian's), against a real server process."""

from __future__ import annotations

import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
ARTIFACTS = Path(__file__).resolve().parents[2] / "artifacts" / "screenshots"
pytestmark = pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="Debian chromium missing")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def server():
    port = free_port()
    exe = Path(sys.executable).with_name("lipclock")
    proc = subprocess.Popen([str(exe), "serve", "--port", str(port)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}"
    for _ in range(200):
        try:
            urllib.request.urlopen(url + "/healthz", timeout=1)
            break
        except OSError:
            time.sleep(0.1)
    else:
        proc.kill()
        raise RuntimeError("server did not start")
    yield url
    proc.terminate()
    proc.wait(timeout=10)


@pytest.fixture(scope="module")
def browser():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=[
            "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
            "--disable-component-update", "--disable-sync", "--no-first-run",
            "--autoplay-policy=no-user-gesture-required"])
        yield b
        b.close()


def test_page_speaks_and_the_mouth_moves_on_the_audio_clock(server, browser):
    page = browser.new_page(viewport={"width": 1000, "height": 700})
    errors: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(server + "/")
    page.wait_for_function("document.getElementById('status').textContent === 'connected'")
    page.click("#speak")
    page.wait_for_function("window.lipclockDebug.audioSample > 4000", timeout=15000)
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
