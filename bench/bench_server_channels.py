"""Independent channels (issue 5): >= 50 channels speak at once, each in real time.

A real `lipclock serve` on loopback; one subscriber per channel (spread over --procs
client processes); all channels are sent a sentence at the same moment (concurrent
POST /speak). Each subscriber checks the issue's rule with bench_server_fanout's
client: audio for second N arrives before playback reaches second N (120 ms playout
buffer, as client/lipclock.js keeps).

    .venv/bin/python bench/bench_server_channels.py [--channels 50] [--utterances 2]
"""

from __future__ import annotations

import argparse
import asyncio
import multiprocessing as mp

import httpx

from bench_server_fanout import SENTENCES, client
from serverutil import running_server


def worker(urls: list[str], n_utt: int, buffer_s: float, ready_q: mp.Queue,
           out_q: mp.Queue) -> None:
    async def run() -> list[tuple[float, int]]:
        readies = [asyncio.Event() for _ in urls]
        tasks = [asyncio.create_task(client(u, r, n_utt, buffer_s))
                 for u, r in zip(urls, readies, strict=True)]
        await asyncio.gather(*(r.wait() for r in readies))
        ready_q.put(len(urls))
        return await asyncio.wait_for(asyncio.gather(*tasks), timeout=300)

    out_q.put(asyncio.run(run()))


async def speak_all(addr: str, channels: list[str], n_utt: int) -> None:
    async with httpx.AsyncClient(base_url=f"http://{addr}", timeout=120) as http:
        for i in range(n_utt):
            rs = await asyncio.gather(*(http.post("/speak", json={
                "text": SENTENCES[(i + j) % len(SENTENCES)], "channel": ch})
                for j, ch in enumerate(channels)))
            for r in rs:
                r.raise_for_status()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--channels", type=int, default=50)
    ap.add_argument("--utterances", type=int, default=2, help="queued per channel")
    ap.add_argument("--procs", type=int, default=2)
    ap.add_argument("--buffer-ms", type=float, default=120.0)
    args = ap.parse_args()
    names = [f"room{i}" for i in range(args.channels)]
    ctx = mp.get_context("spawn")
    with running_server() as (addr, _):
        urls = [f"ws://{addr}/ws?channel={n}" for n in names]
        ready_q, out_q = ctx.Queue(), ctx.Queue()
        parts = [urls[i::args.procs] for i in range(args.procs)]
        procs = [ctx.Process(target=worker, args=(p, args.utterances, args.buffer_ms / 1000,
                                                  ready_q, out_q)) for p in parts if p]
        for p in procs:
            p.start()
        connected = sum(ready_q.get(timeout=120) for _ in procs)
        asyncio.run(speak_all(addr, names, args.utterances))
        results = [r for _ in procs for r in out_q.get(timeout=300)]
        for p in procs:
            p.join(timeout=30)
    ok = sum(1 for worst, _ in results if worst <= 0)
    print(f"channels={connected}, {args.utterances} utterances each, all started at once; "
          f"playout buffer {args.buffer_ms:.0f} ms")
    print(f"channels in real time: {ok}/{connected} (goal: >= 50); worst lateness "
          f"{max(w for w, _ in results) * 1000:.1f} ms")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
