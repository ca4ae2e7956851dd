"""Device-clock sync (issue 5): a display's estimate of the device sample, through jitter.

A real `lipclock serve` in device mode (simulated device) on loopback. A display client
connects through a TCP proxy that delays every segment by 20-80 ms (random, order kept,
each direction). It keeps its own clock (the monotonic clock plus an unknown skew),
estimates its offset to the server clock from ping/pong, keeping the lowest-RTT
exchanges, and predicts the device sample at that moment from the latest `clock` message.
Truth comes from a direct connection: server and bench share this machine's monotonic
clock, so a clock message {device_sample, server_time_s} gives the device position exactly.

Goal: |estimate - truth| within 10 ms at p95.

    .venv/bin/python bench/bench_clock_sync.py [--seconds 12] [--jitter-ms 20 80]
"""

from __future__ import annotations

import argparse
import asyncio
import json
import random
import statistics
import time

import httpx
import websockets

from serverutil import free_port, jitter_proxy, percentile, running_server

SKEW_S = 1234.567  # the display's clock is not the server's
TEXT = ("This is a long announcement for the kiosk display test. " * 12).strip()


class ClockView:
    """The latest clock message a client has seen."""

    def __init__(self) -> None:
        self.sample = 0
        self.server_time = 0.0
        self.sample_rate = 16000

    def update(self, msg: dict) -> None:
        self.sample, self.server_time = msg["device_sample"], msg["server_time_s"]


async def run(addr: str, port: int, seconds: float, jitter: tuple[float, float]
              ) -> list[float]:
    rng = random.Random(7)
    pport = free_port()
    proxy = await jitter_proxy(pport, port, jitter[0] / 1000, jitter[1] / 1000, rng)
    direct, display = ClockView(), ClockView()
    pings: list[tuple[float, float]] = []  # (rtt, offset) in the display's clock
    errors: list[float] = []
    stop = asyncio.Event()

    async def listen(url: str, view: ClockView, ping: bool) -> None:
        async with websockets.connect(url, max_size=None, compression=None) as ws:
            view.sample_rate = json.loads(await ws.recv())["sample_rate"]

            async def pinger() -> None:
                while not stop.is_set():
                    await ws.send(json.dumps({"type": "ping",
                                              "t_client": time.monotonic() + SKEW_S}))
                    await asyncio.sleep(0.1)

            task = asyncio.create_task(pinger()) if ping else None
            while not stop.is_set():
                try:
                    raw = await asyncio.wait_for(ws.recv(), timeout=0.2)
                except TimeoutError:
                    continue
                if isinstance(raw, bytes):
                    continue
                msg = json.loads(raw)
                if msg["type"] == "clock":
                    view.update(msg)
                elif msg["type"] == "pong":
                    t_recv = time.monotonic() + SKEW_S
                    rtt = t_recv - msg["t_client"]
                    pings.append((rtt, msg["server_time_s"] - (msg["t_client"] + t_recv) / 2))
            if task:
                task.cancel()

    tasks = [asyncio.create_task(listen(f"ws://{addr}/ws?channel=k", direct, False)),
             asyncio.create_task(listen(f"ws://127.0.0.1:{pport}/ws?channel=k", display,
                                        True))]
    await asyncio.sleep(2.0)  # pings accumulate
    async with httpx.AsyncClient(base_url=f"http://{addr}") as http:
        (await http.post("/speak", json={"text": TEXT, "channel": "k"})).raise_for_status()
    await asyncio.sleep(1.0)
    t_end = time.monotonic() + seconds
    while time.monotonic() < t_end:
        await asyncio.sleep(0.037)
        if direct.sample == 0 or display.sample == 0 or len(pings) < 5:
            continue
        best = sorted(pings)[: max(3, len(pings) // 10)]  # lowest-RTT exchanges
        offset = statistics.median(o for _, o in best)
        t = time.monotonic()
        sr = display.sample_rate
        est = display.sample + ((t + SKEW_S) + offset - display.server_time) * sr
        truth = direct.sample + (t - direct.server_time) * sr
        errors.append((est - truth) / sr * 1000.0)
    stop.set()
    await asyncio.gather(*tasks, return_exceptions=True)
    proxy.close()
    return errors


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=12.0)
    ap.add_argument("--jitter-ms", type=float, nargs=2, default=(20.0, 80.0))
    args = ap.parse_args()
    with running_server({"LIPCLOCK_CLOCK": "device",
                         "LIPCLOCK_AUDIO_DEVICE": "simulated"}) as (addr, _):
        port = int(addr.rsplit(":", 1)[1])
        errs = asyncio.run(run(addr, port, args.seconds, tuple(args.jitter_ms)))
    a = [abs(e) for e in errs]
    print(f"display estimate of the device sample through a {args.jitter_ms[0]:.0f}-"
          f"{args.jitter_ms[1]:.0f} ms jitter proxy, {len(errs)} estimates while playing")
    print(f"  |error| p50 {statistics.median(a):.2f} ms, p95 {percentile(a, 95):.2f} ms "
          f"(goal p95 <= 10 ms), max {max(a):.2f} ms; mean signed {statistics.mean(errs):+.2f} ms")


if __name__ == "__main__":
    main()
