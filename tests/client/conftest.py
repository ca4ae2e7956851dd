"""Fixtures for the real-browser tests: a server process and headless Chromium."""

from __future__ import annotations

import pytest
from browser_util import ARGS, CHROMIUM, start_server


@pytest.fixture(scope="module")
def server():
    url, proc = start_server()
    yield url
    proc.terminate()
    proc.wait(timeout=10)


@pytest.fixture(scope="module")
def device_server():
    url, proc = start_server({"LIPCLOCK_CLOCK": "device", "LIPCLOCK_AUDIO_DEVICE": "simulated"})
    yield url
    proc.terminate()
    proc.wait(timeout=10)


@pytest.fixture(scope="module")
def playwright():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        yield p


@pytest.fixture(scope="module")
def browser(playwright):
    b = playwright.chromium.launch(executable_path=CHROMIUM,
                                   args=[*ARGS, "--autoplay-policy=no-user-gesture-required"])
    yield b
    b.close()
