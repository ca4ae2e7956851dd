"""The client library against a misbehaving server: malformed messages and an unknown
protocol version each give one clear console warning, never an exception, and the client
keeps working (issue #6, bad input and faults)."""

from __future__ import annotations

import json
import threading

import pytest
from browser_util import HAVE_CHROMIUM, free_port
from websockets.sync.server import serve

pytestmark = pytest.mark.skipif(not HAVE_CHROMIUM, reason="Debian chromium missing")

HELLO = {"type": "hello", "protocol_version": 1, "sample_rate": 16000, "channel": "x"}
BAD = [
    "this is not JSON {",
    json.dumps([1, 2, 3]),
    json.dumps({"no": "type"}),
    json.dumps({"type": "teleport"}),
    json.dumps({"type": "start", "utterance_id": 1}),             # fields missing
    json.dumps({"type": "mouth", "utterance_id": 1, "first_frame": "zero",
                "frames": [], "lip_gap": []}),
    json.dumps({"type": "end", "utterance_id": -4, "end_sample": 0}),
]


@pytest.fixture(scope="module")
def rogue_server():
    """A WebSocket server that greets each client, then sends what its path asks for."""
    def handler(ws):
        if ws.request.path.startswith("/future"):
            ws.send(json.dumps({**HELLO, "protocol_version": 99}))
            ws.send(json.dumps({"type": "start", "utterance_id": 1, "sample_rate": 16000,
                                "num_samples": 100, "mouth_rate_hz": 100, "words": [],
                                "phones": [], "visemes": [], "mouth_nodes": []}))
        else:
            ws.send(json.dumps(HELLO))
            for frame in BAD:
                ws.send(frame)
            ws.send(b"XXXX" + bytes(40))                             # not an audio frame
        try:
            for _ in ws:   # keep the connection open until the client leaves
                pass
        except Exception:
            pass

    port = free_port()
    with serve(handler, "127.0.0.1", port) as srv:
        t = threading.Thread(target=srv.serve_forever, daemon=True)
        t.start()
        yield f"ws://127.0.0.1:{port}"
        srv.shutdown()


def _watch(server, browser, ws_url):
    page = browser.new_page()
    warnings: list[str] = []
    errors: list[str] = []
    page.on("console", lambda m: (warnings if m.type == "warning" else errors
                                  if m.type == "error" else []).append(m.text))
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.route("**/favicon.ico", lambda route: route.fulfill(status=204))
    page.goto(server + "/healthz")   # any page of the server's origin will do
    page.evaluate("""async (url) => {
        const { LipclockClient } = await import('/client/lipclock.js');
        const c = new LipclockClient({ url });
        window.c = c;
        await c.unlock();
        let frames = 0;
        c.animate(() => { frames++; });
        window.frames = () => frames;
        await new Promise((r) => setTimeout(r, 800));
    }""", ws_url)
    return page, warnings, errors


def test_each_malformed_message_is_one_warning_and_nothing_breaks(server, browser, rogue_server):
    page, warnings, errors = _watch(server, browser, rogue_server + "/bad")
    assert not errors, errors
    malformed = [w for w in warnings if "malformed" in w or "unknown message" in w
                 or "bad audio" in w]
    assert len(malformed) == len(BAD) + 1, warnings
    assert page.evaluate("window.c.utt") is None          # no half-built utterance
    assert page.evaluate("window.c.ws.readyState") == 1   # still connected
    assert page.evaluate("window.frames()") > 5           # the animation loop runs on
    page.close()


def test_an_unknown_protocol_version_warns_once_and_is_ignored(server, browser, rogue_server):
    page, warnings, errors = _watch(server, browser, rogue_server + "/future")
    assert not errors, errors
    assert len(warnings) == 1 and "protocol 99" in warnings[0], warnings
    assert page.evaluate("window.c.utt") is None
    page.close()
