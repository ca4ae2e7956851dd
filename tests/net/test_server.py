"""The server through its real ASGI app: HTTP routes, WebSocket streaming order, bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
from fastapi.testclient import TestClient

from lipclock.config import Settings
from lipclock.net.app import create_app
from lipclock.net.protocol import unpack_audio


@pytest.fixture()
def client():
    with TestClient(create_app(Settings())) as c:
        yield c


def recv_utterance(ws) -> tuple[list, list]:
    """Messages of one utterance in arrival order: ('json', msg) or ('audio', (uid, first, pcm))."""
    events, kinds = [], []
    while True:
        m = ws.receive()
        if m.get("bytes") is not None:
            events.append(("audio", unpack_audio(m["bytes"])))
        else:
            msg = json.loads(m["text"])
            events.append(("json", msg))
            if msg["type"] == "end":
                break
        kinds.append(events[-1][0] if events[-1][0] == "audio" else events[-1][1]["type"])
    return events, kinds


def test_http_routes(client):
    assert client.get("/healthz").json()["status"] == "ok"
    v = client.get("/voices").json()
    assert {x["name"] for x in v["voices"]} >= {"adult-low", "adult-high"}
    r = client.post("/speak", json={"text": "Hello there.", "channel": "lobby"})
    assert r.status_code == 200
    body = r.json()
    assert body["sample_rate"] == 16000 and body["words"][0]["text"] == "hello"
    wav = client.get(body["audio_url"].replace("http://testserver", ""))
    assert wav.status_code == 200 and wav.content[:4] == b"RIFF"
    marks = client.get(body["marks_url"].replace("http://testserver", "")).json()
    assert marks["mouth"]["frames"]
    r = client.post("/speak", json={"text": "A file please."}, headers={"Accept": "audio/wav"})
    assert r.headers["content-type"] == "audio/wav" and "x-marks-url" in r.headers
    assert "lipclock_utterances_total 2" in client.get("/metrics").text
    assert client.get("/docs").status_code == 200
    mesh = client.get("/mesh").json()
    assert mesh["units"] == "mm" and mesh["nodes"][:2] == ["corner_l", "corner_r"]
    assert len(mesh["rest"]) == len(mesh["nodes"]) and mesh["triangles"] and mesh["edges"]


def test_spring_constants_per_request_change_the_mouth(client):
    defaults = client.get("/voices").json()["spring_params"]
    assert defaults["lips.stiffness"] > 0 and defaults["jaw.damping"] > 0
    text = "Papa, a big bowl of mashed bananas."

    def gaps(**params):
        r = client.post("/speak", json={"text": text, "spring_params": params or None})
        assert r.status_code == 200
        marks = client.get(r.json()["marks_url"].replace("http://testserver", "")).json()
        return marks["mouth"]["measures"]["lip_gap"]

    base, stiff = gaps(), gaps(**{"lips.stiffness": 4 * defaults["lips.stiffness"]})
    assert base == gaps(**{"lips.stiffness": defaults["lips.stiffness"]})  # same constants
    assert base != stiff and max(stiff) > max(base)  # a stiffer lip spring opens further


@pytest.mark.parametrize("payload,status,code", [
    ({"text": ""}, 422, None),
    ({"text": "   "}, 400, "empty_text"),
    ({"text": "hi", "voice": "robot"}, 400, "unknown_choice"),
    ({"text": "hi", "rate_wpm": 9000}, 400, "out_of_range"),
    ({"text": "hi", "channel": "no spaces!"}, 400, "bad_channel"),
    ({"text": "x" * 6000}, 400, "text_too_long"),
    ({"text": "hi", "spring_params": {"lips.stiffnes": 5}}, 400, "unknown_choice"),
    ({"text": "hi", "spring_params": {"lips.damping": -2}}, 400, "out_of_range"),
    ({"text": "hi", "spring_params": {"lips.mass": 1e-4, "lips.stiffness": 1e5}}, 400, "bad_input"),
    ({"text": "hi", "mouth_model": "linear", "spring_params": {"lips.damping": 1}}, 400,
     "unknown_choice"),
    ({"text": "hi", "spring_params": {"lips.damping": "soft"}}, 422, None),
])
def test_http_bad_input_is_4xx_with_reason(client, payload, status, code):
    r = client.post("/speak", json=payload)
    assert r.status_code == status
    if code:
        assert r.json()["error"]["code"] == code and r.json()["error"]["reason"]
    assert client.get("/utterances/999999.wav").status_code == 404


def test_ws_stream_order_mouth_before_audio_and_exact_samples(client):
    with client.websocket_connect("/ws?channel=t1") as ws:
        hello = json.loads(ws.receive_text())
        assert hello["type"] == "hello" and hello["protocol_version"] == 1
        ws.send_text(json.dumps({"type": "speak", "text": "Mouth data comes first, always."}))
        events, kinds = recv_utterance(ws)
    assert kinds[0] == "start"
    start = events[0][1]
    mouth_until = 0
    audio = []
    for kind, payload in events[1:]:
        if kind == "json" and payload["type"] == "mouth":
            mouth_until = payload["end_sample"]
        elif kind == "audio":
            uid, first, pcm = payload
            samples = np.frombuffer(pcm, dtype="<i2")
            assert uid == start["utterance_id"]
            assert first == sum(len(a) for a in audio)  # contiguous, stamped with sample index
            assert mouth_until >= first + len(samples)  # its mouth data already arrived
            audio.append(samples)
    end = events[-1][1]
    assert end["end_sample"] == start["num_samples"] == sum(len(a) for a in audio)
    assert not end["stopped"]


def test_ws_fans_out_to_every_subscriber(client):
    with client.websocket_connect("/ws?channel=fan") as a, \
            client.websocket_connect("/ws?channel=fan") as b:
        a.receive_text()
        b.receive_text()
        client.post("/speak", json={"text": "To both of you.", "channel": "fan"})
        ea, _ = recv_utterance(a)
        eb, _ = recv_utterance(b)
    assert [k for k, _ in ea] == [k for k, _ in eb]


def test_ws_bad_messages_get_typed_errors_and_the_connection_survives(client):
    with client.websocket_connect("/ws?channel=bad") as ws:
        ws.receive_text()
        cases = [("{not json", "bad_json"), ('{"type": "dance"}', "unknown_type"),
                 ('[1, 2]', "unknown_type"), ('{"type": "speak"}', "bad_message"),
                 ('{"type": "speak", "text": "hi", "rate_wpm": 1}', "out_of_range"),
                 ("x" * 70000, "too_large")]
        for raw, code in cases:
            ws.send_text(raw)
            msg = json.loads(ws.receive_text())
            assert msg["type"] == "error" and msg["code"] == code and msg["reason"]
        ws.send_bytes(b"\x00\x01")
        assert json.loads(ws.receive_text())["code"] == "binary_not_expected"
        ws.send_text(json.dumps({"type": "ping", "t_client": 5.0}))
        pong = json.loads(ws.receive_text())
        assert pong["type"] == "pong" and pong["t_client"] == 5.0


def test_ws_incremental_text_speaks_each_sentence(client):
    with client.websocket_connect("/ws?channel=chat") as ws:
        ws.receive_text()
        for piece in ["Hello the", "re. How are", " you? I am fi", "ne"]:
            ws.send_text(json.dumps({"type": "text.append", "text": piece}))
        ws.send_text(json.dumps({"type": "text.flush"}))
        texts = []
        for _ in range(3):
            events, _ = recv_utterance(ws)
            texts.append(events[0][1]["text"])
    assert texts == ["Hello there.", "How are you?", "I am fine"]


def test_ws_stop_cuts_the_utterance_and_says_where(client):
    long_text = "This is a long answer that goes on. " * 12
    with client.websocket_connect("/ws?channel=stop") as ws:
        ws.receive_text()
        ws.send_text(json.dumps({"type": "speak", "text": long_text}))
        start = json.loads(ws.receive_text())
        assert start["type"] == "start"
        ws.send_text(json.dumps({"type": "stop"}))
        while True:
            m = ws.receive()
            if m.get("text") and json.loads(m["text"])["type"] == "end":
                end = json.loads(m["text"])
                break
    assert end["stopped"] and end["end_sample"] < start["num_samples"]


def test_keys_and_scopes():
    s = Settings(speak_keys=["s3cret"], view_keys=["look"])
    with TestClient(create_app(s)) as c:
        assert c.post("/speak", json={"text": "hi"}).status_code == 401
        assert c.post("/speak", json={"text": "hi"}, headers={"X-API-Key": "look"}).status_code \
            == 403
        assert c.post("/speak", json={"text": "hi"},
                      headers={"Authorization": "Bearer s3cret"}).status_code == 200
        with c.websocket_connect("/ws?key=look&channel=viewers") as ws:
            ws.receive_text()
            ws.send_text(json.dumps({"type": "speak", "text": "hi"}))
            assert json.loads(ws.receive_text())["code"] == "forbidden"
        from starlette.websockets import WebSocketDisconnect

        with pytest.raises(WebSocketDisconnect) as exc, c.websocket_connect("/ws?key=wrong") as ws:
            ws.receive_text()
        assert exc.value.code == 4001
