"""Latency from POST /speak (a 20-word sentence) to the first audio frame on a subscribed
WebSocket, against a real `lipclock serve` on loopback.

Goal (issue 5): p50 <= 25 ms, p99 <= 60 ms; the first mouth frame arrives no later than
the first audio frame. Each request waits for the previous utterance to end.

    .venv/bin/python bench/bench_server_latency.py [--requests 100]
"""

from __future__ import annotations

import argparse
import asyncio
import json
import statistics
import time

import httpx
import websockets

from serverutil import percentile, running_server

SENTENCE = ("Please remember that the north elevators are closed for repairs today, so use "
            "the stairs near the main entrance instead.")


async def run(url: str, n: int) -> tuple[list[float], int]:
    lat: list[float] = []
    mouth_late = 0
    async with websockets.connect(f"ws://{url}/ws?channel=lat", max_size=None) as ws, \
            httpx.AsyncClient(base_url=f"http://{url}") as http:
        json.loads(await ws.recv())  # hello
        for i in range(n + 3):
            t0 = time.perf_counter()
            post = asyncio.create_task(http.post("/speak", json={"text": SENTENCE,
                                                                 "channel": "lat"}))
            first_audio = first_mouth = None
            while True:
                msg = await ws.recv()
                now = time.perf_counter()
                if isinstance(msg, bytes):
                    first_audio = first_audio or now
                    continue
                m = json.loads(msg)
                if m["type"] == "mouth" and first_mouth is None:
                    first_mouth = now
                if m["type"] == "end":
                    break
            await post
            if i >= 3:  # warm-up
                assert first_audio is not None
                lat.append(1000 * (first_audio - t0))
                mouth_late += first_mouth is None or first_mouth > first_audio
    return lat, mouth_late


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--requests", type=int, default=100)
    args = ap.parse_args()
    with running_server() as (url, _):
        lat, late = asyncio.run(run(url, args.requests))
    print(f"POST /speak -> first audio frame on a subscribed WebSocket ({len(lat)} requests)")
    print(f"  p50 {statistics.median(lat):6.1f} ms   (goal <= 25 ms)")
    print(f"  p99 {percentile(lat, 99):6.1f} ms   (goal <= 60 ms)")
    print(f"  max {max(lat):6.1f} ms")
    print(f"  first mouth frame after first audio frame: {late} times (goal 0)")


if __name__ == "__main__":
    main()
