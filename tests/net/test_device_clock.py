"""Device-clock (kiosk) mode: the simulated device and the server's clock messages."""

from __future__ import annotations

import json
import time

import numpy as np
from fastapi.testclient import TestClient

from lipclock.config import Settings
from lipclock.net.app import create_app
from lipclock.net.clock import SimulatedDevice, open_device


def test_simulated_device_plays_in_real_time_and_idles_when_empty():
    dev = SimulatedDevice(16000)
    assert dev.position()[0] == 0
    first = dev.enqueue(np.zeros(1600, dtype=np.int16))  # 100 ms
    assert first == 0
    assert dev.enqueue(np.zeros(1600, dtype=np.int16)) == 1600  # queued right after
    time.sleep(0.05)
    pos, at = dev.position()
    assert 500 <= pos <= 1600 and abs(at - time.monotonic()) < 0.05
    time.sleep(0.25)
    assert dev.position()[0] == 3200  # played everything, then the clock waits
    start = dev.enqueue(np.zeros(160, dtype=np.int16))
    assert start == 3200
    assert dev.stop() <= 3360 and dev.position()[0] <= 3360
    assert isinstance(open_device(16000, "simulated"), SimulatedDevice)


def test_server_in_device_mode_broadcasts_the_device_clock():
    with TestClient(create_app(Settings(clock="device", audio_device="simulated"))) as c, \
            c.websocket_connect("/ws?channel=kiosk") as ws:
        hello = json.loads(ws.receive_text())
        assert hello["clock"] == "device"
        first_clock = json.loads(ws.receive_text())
        assert first_clock["type"] == "clock"
        ws.send_text(json.dumps({"type": "speak", "text": "The kiosk speaker talks now."}))
        start, clocks = None, []
        while start is None or len(clocks) < 3:
            m = ws.receive()
            if m.get("text") is None:
                continue
            msg = json.loads(m["text"])
            if msg["type"] == "start":
                start = msg
            elif msg["type"] == "clock" and start is not None:  # while it plays
                clocks.append(msg)
        assert isinstance(start["device_start"], int)
        samples = [c["device_sample"] for c in clocks]
        times = [c["server_time_s"] for c in clocks]
        assert samples == sorted(samples) and samples[-1] > samples[0]
        rate = (samples[-1] - samples[0]) / (times[-1] - times[0])
        assert 0.8 * 16000 < rate < 1.2 * 16000  # the device clock runs at the sample rate
        ws.send_text(json.dumps({"type": "stop"}))
        while True:
            m = ws.receive()
            msg = json.loads(m["text"]) if m.get("text") else {}
            if msg.get("type") == "end" and msg["stopped"]:  # not the stream-complete end
                end = msg
                break
        assert end["stopped"] and end["end_sample"] < start["num_samples"]
