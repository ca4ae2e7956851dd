"""Fuzzing the HTTP and WebSocket boundaries, and leak checks (issue 5, bad input and faults)."""

from __future__ import annotations

import json
import threading

import pytest
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lipclock.config import Settings
from lipclock.net.app import create_app
from lipclock.net.protocol import SERVER_MESSAGE


@pytest.fixture(scope="module")
def client():
    with TestClient(create_app(Settings(max_message_bytes=4096))) as c:
        yield c


_scalars = st.one_of(st.none(), st.booleans(), st.integers(), st.floats(allow_nan=True),
                     st.text(max_size=40))
_json = st.recursive(_scalars, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=10), inner, max_size=4)),
    max_leaves=12)
_messages = st.one_of(
    _json,
    st.fixed_dictionaries({"type": st.sampled_from(["speak", "text.append", "text.flush",
                                                    "stop", "ping", "pong", "hello", ""])},
                          optional={"text": _scalars, "voice": _scalars, "rate_wpm": _scalars,
                                    "pitch_hz": _scalars, "mouth_model": _scalars,
                                    "t_client": _scalars, "extra": _scalars,
                                    "spring_params": _json}),
)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                   HealthCheck.function_scoped_fixture])
@given(st.lists(st.one_of(_messages.map(lambda m: json.dumps(m, allow_nan=True)),
                          st.text(max_size=60), st.binary(max_size=64)), min_size=1,
                max_size=4))
def test_fuzz_websocket_messages_get_typed_replies_and_the_socket_survives(client, frames):
    with client.websocket_connect("/ws?channel=fuzz") as ws:
        assert json.loads(ws.receive_text())["type"] == "hello"
        for frame in frames:
            if isinstance(frame, bytes):
                ws.send_bytes(frame)
            else:
                ws.send_text(frame)
        ws.send_text(json.dumps({"type": "stop"}))
        ws.send_text(json.dumps({"type": "ping", "t_client": 1.0}))
        while True:  # every reply is a valid server message; the pong proves we're alive
            m = ws.receive()
            if m.get("bytes") is not None:
                continue
            msg = SERVER_MESSAGE.validate_json(m["text"])
            if msg.type == "pong":
                break


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                  HealthCheck.function_scoped_fixture])
@given(_json)
def test_fuzz_speak_endpoint_never_500(client, body):
    raw = json.dumps(body, allow_nan=True)  # NaN/Infinity tokens too, as a hostile client may
    r = client.post("/speak", content=raw, headers={"content-type": "application/json"})
    assert r.status_code < 500
    if r.status_code >= 400:
        assert "error" in r.json() or "detail" in r.json()


def _get_routes():
    """Every GET route the app has, schema or not: a new route is fuzzed without edits."""
    from fastapi.routing import APIRoute
    app = create_app(Settings())
    return sorted(r.path for r in app.routes if isinstance(r, APIRoute) and "GET" in r.methods)


_segment = st.one_of(st.text(max_size=30), st.sampled_from(
    ["..", "../..", "%2e%2e", "0", "-1", "99999999999999999999", "app.js", "lipclock.js",
     "morphs.tsv", "dynamics.toml", "%00", "a" * 300]))


def test_fuzz_covers_every_get_route():
    assert {"/", "/voices", "/mesh", "/healthz", "/metrics", "/utterances/{uid}.wav",
            "/client/{name:path}"} <= set(_get_routes())


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                   HealthCheck.function_scoped_fixture])
@given(st.sampled_from(_get_routes()), _segment,
       st.dictionaries(st.text(min_size=1, max_size=8), st.text(max_size=20), max_size=3))
def test_fuzz_every_get_endpoint_never_500(client, route, segment, query):
    from urllib.parse import quote
    path = route
    for param in ("{uid}", "{name:path}", "{name}"):
        path = path.replace(param, quote(segment, safe="/%"))
    r = client.get(path, params=query)
    assert r.status_code < 500, (path, r.status_code)
    if r.status_code >= 400:
        assert "error" in r.json() or "detail" in r.json()


def test_connect_disconnect_cycles_leave_nothing_behind():
    app = create_app(Settings())
    with TestClient(app) as c:
        for _ in range(1000):
            with c.websocket_connect("/ws?channel=cycle") as ws:
                ws.receive_text()
        assert app.state.metrics.connections == 0
        assert app.state.broker.channels == {}


def test_killing_a_client_mid_stream_and_stop_during_first_chunk_leak_nothing():
    app = create_app(Settings())
    threads_before = threading.active_count()
    with TestClient(app) as c:
        for _ in range(20):
            with c.websocket_connect("/ws?channel=kill") as ws:
                ws.receive_text()
                ws.send_text(json.dumps({"type": "speak", "text": "A long answer. " * 20}))
                ws.receive()  # start: then drop the connection mid-utterance
        with c.websocket_connect("/ws?channel=kill") as ws:
            ws.receive_text()
            for _ in range(20):  # stop straight away, during the first chunk
                ws.send_text(json.dumps({"type": "speak", "text": "Stop me now please."}))
                ws.send_text(json.dumps({"type": "stop"}))
            ws.send_text(json.dumps({"type": "ping", "t_client": 0}))
            while True:
                m = ws.receive()
                if m.get("text") and json.loads(m["text"]).get("type") == "pong":
                    break
        # let the channel worker finish what it had
        for _ in range(200):
            ch = app.state.broker.channels.get("kill")
            if ch is None or (ch.current is None and ch.pending.empty()):
                break
            threading.Event().wait(0.02)
        assert app.state.metrics.connections == 0
        ch = app.state.broker.channels.get("kill")
        assert ch is None or not ch.subscribers
    assert threading.active_count() <= threads_before + 1
