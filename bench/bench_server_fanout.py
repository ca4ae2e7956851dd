"""Fan-out bench (issue 5): N subscribers on one channel receive continuous speech without underrun.

Starts a real server (`lipclock serve`) on loopback, connects N WebSocket
clients (default 200) to one channel from this separate client process, then
POSTs several sentences back to back. A client "underruns" if the audio frame
starting at sample s arrives later than s / sample_rate seconds after that
client's first audio frame (plus --buffer-ms of playout buffer, as a browser
would keep). Prints clients without underrun beside the goal (all N).

    .venv/bin/python bench/bench_server_fanout.py --clients 200
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import struct
import subprocess
import sys
import time

import socket

import httpx
import websockets

SENTENCES = [
    "The quick brown fox jumped over the lazy dog while the farmer watched from "
    "behind the old red barn door.",
    "Please remember to bring your umbrella tomorrow because the weather report says "
    "heavy rain will fall all afternoon.",
    "Our meeting has been moved to Thursday morning so that everyone from the "
    "northern office can join us in person.",
]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


async def wait_up(base: str, proc: subprocess.Popen[bytes]) -> None:
    async with httpx.AsyncClient() as c:
        for _ in range(300):
            if proc.poll() is not None:
                raise SystemExit("server exited during start")
            try:
                if (await c.get(base + "/healthz")).status_code == 200:
                    return
            except httpx.HTTPError:
                pass
            await asyncio.sleep(0.1)
    raise SystemExit("server did not come up")

HEADER = struct.Struct("<4sIQ")


async def client(url: str, ready: asyncio.Event, done: asyncio.Event, n_utt: int,
                 sample_rate_box: list[int], buffer_s: float) -> tuple[float, int]:
    """Return (worst lateness in s, audio frames received)."""
    async with websockets.connect(url, max_size=None) as ws:
        hello = json.loads(await ws.recv())
        sample_rate_box[0] = int(hello["sample_rate"])
        ready.set()
        worst = -1e9
        frames = 0
        ends = 0
        origin: tuple[float, int, int] | None = None  # (arrival, utt id, first sample)
        play_offset_s = 0.0
        while ends < n_utt:
            msg = await ws.recv()
            now = time.perf_counter()
            if isinstance(msg, bytes):
                _, uid, first = HEADER.unpack_from(msg)
                frames += 1
                if origin is None:
                    origin = (now, uid, first)
                    play_offset_s = 0.0
                due = origin[0] + buffer_s + play_offset_s + first / sample_rate_box[0]
                worst = max(worst, now - due)
            elif json.loads(msg).get("type") == "end":
                ends += 1
                origin = None
        return worst, frames


async def main_async(args: argparse.Namespace) -> int:
    port = free_port()
    base = f"http://127.0.0.1:{port}"
    proc = subprocess.Popen([os.path.join(os.path.dirname(sys.executable), "lipclock"), "serve",
                             "--host", "127.0.0.1", "--port", str(port)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        await wait_up(base, proc)
        url = f"ws://127.0.0.1:{port}/ws?channel=fan"
        sr = [0]
        readies = [asyncio.Event() for _ in range(args.clients)]
        done = asyncio.Event()
        tasks = [asyncio.create_task(client(url, r, done, args.utterances, sr, args.buffer_ms / 1000))
                 for r in readies]
        await asyncio.gather(*(r.wait() for r in readies))
        async with httpx.AsyncClient(timeout=60) as http:
            for i in range(args.utterances):
                (await http.post(base + "/speak", json={"text": SENTENCES[i % len(SENTENCES)],
                                                        "channel": "fan"})).raise_for_status()
        results = await asyncio.wait_for(asyncio.gather(*tasks), timeout=300)
        ok = sum(1 for worst, _ in results if worst <= 0)
        worst_ms = max(w for w, _ in results) * 1000
        frames = sorted(f for _, f in results)
        print(f"clients={args.clients} utterances={args.utterances} buffer={args.buffer_ms} ms")
        print(f"clients without underrun: {ok}/{args.clients} (goal all); worst lateness "
              f"{worst_ms:.1f} ms; audio frames per client min {frames[0]} median "
              f"{frames[len(frames) // 2]} max {frames[-1]}")
    finally:
        proc.terminate()
        proc.wait(timeout=10)
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--clients", type=int, default=200)
    ap.add_argument("--utterances", type=int, default=3)
    ap.add_argument("--buffer-ms", type=float, default=100.0)
    return asyncio.run(main_async(ap.parse_args()))


if __name__ == "__main__":
    raise SystemExit(main())
