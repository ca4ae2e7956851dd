"""Fan-out bench (issue 5): N subscribers on one channel receive continuous speech without underrun.

Starts a real server (`lipclock serve`) on loopback and connects N WebSocket clients
(default 200) to one channel from --procs separate client processes (so the bench's own
JSON decoding does not become the bottleneck), then POSTs several sentences back to back.
A client "underruns" if audio for second N of an utterance arrives after playback
reaches second N: a frame starting at sample s is due floor(s / sample_rate) seconds
after that client's first audio frame of the utterance, plus --buffer-ms of playout
buffer (as a browser would keep). Prints clients without
underrun beside the goal (all N).

    .venv/bin/python bench/bench_server_fanout.py --clients 200 [--procs 4]
"""

from __future__ import annotations

import argparse
import asyncio
import json
import multiprocessing as mp
import struct
import time

import httpx
import websockets

from serverutil import running_server

HEADER = struct.Struct("<4sIQ")
SENTENCES = [
    "The quick brown fox jumped over the lazy dog while the farmer watched from "
    "behind the old red barn door.",
    "Please remember to bring your umbrella tomorrow because the weather report says "
    "heavy rain will fall all afternoon.",
    "Our meeting has been moved to Thursday morning so that everyone from the "
    "northern office can join us in person.",
]


async def client(url: str, ready: asyncio.Event, n_utt: int, buffer_s: float
                 ) -> tuple[float, int]:
    """Return (worst lateness in s, audio frames received)."""
    async with websockets.connect(url, max_size=None, compression=None) as ws:
        sample_rate = int(json.loads(await ws.recv())["sample_rate"])
        ready.set()
        worst, frames, ends = -1e9, 0, 0
        origin: float | None = None
        while ends < n_utt:
            msg = await ws.recv()
            now = time.perf_counter()
            if isinstance(msg, bytes):
                _, _, first = HEADER.unpack_from(msg)
                frames += 1
                if origin is None:
                    origin = now
                # the rule: data for second N must arrive before playback
                # reaches second N (stricter than the chunk's own start time)
                second = first // sample_rate
                worst = max(worst, now - (origin + buffer_s + second))
            elif msg.startswith('{"type":"end"'):  # delivery is measured, not parsing
                ends += 1
                origin = None
        return worst, frames


def worker(url: str, n: int, n_utt: int, buffer_s: float, ready_q: mp.Queue,
           out_q: mp.Queue) -> None:
    async def run() -> list[tuple[float, int]]:
        readies = [asyncio.Event() for _ in range(n)]
        tasks = [asyncio.create_task(client(url, r, n_utt, buffer_s)) for r in readies]
        await asyncio.gather(*(r.wait() for r in readies))
        ready_q.put(n)
        return await asyncio.wait_for(asyncio.gather(*tasks), timeout=300)

    out_q.put(asyncio.run(run()))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clients", type=int, default=200)
    ap.add_argument("--procs", type=int, default=4, help="client processes")
    ap.add_argument("--utterances", type=int, default=3)
    ap.add_argument("--buffer-ms", type=float, default=120.0,
                    help="playout buffer; 120 ms is client/lipclock.js jitterBufferS")
    args = ap.parse_args()
    ctx = mp.get_context("spawn")
    with running_server() as (addr, _):
        url = f"ws://{addr}/ws?channel=fan"
        ready_q, out_q = ctx.Queue(), ctx.Queue()
        shares = [args.clients // args.procs + (i < args.clients % args.procs)
                  for i in range(args.procs)]
        procs = [ctx.Process(target=worker, args=(url, n, args.utterances,
                                                  args.buffer_ms / 1000, ready_q, out_q))
                 for n in shares if n]
        for p in procs:
            p.start()
        connected = sum(ready_q.get(timeout=120) for _ in procs)
        with httpx.Client(base_url=f"http://{addr}", timeout=60) as http:
            for i in range(args.utterances):
                http.post("/speak", json={"text": SENTENCES[i % len(SENTENCES)],
                                          "channel": "fan"}).raise_for_status()
        results = [r for _ in procs for r in out_q.get(timeout=300)]
        for p in procs:
            p.join(timeout=30)
    ok = sum(1 for worst, _ in results if worst <= 0)
    frames = sorted(f for _, f in results)
    print(f"clients={connected} in {len(procs)} processes, utterances={args.utterances}, "
          f"playout buffer {args.buffer_ms:.0f} ms")
    print(f"clients without underrun: {ok}/{connected} (goal: all); worst lateness "
          f"{max(w for w, _ in results) * 1000:.1f} ms; audio frames per client "
          f"min {frames[0]} median {frames[len(frames) // 2]} max {frames[-1]}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
