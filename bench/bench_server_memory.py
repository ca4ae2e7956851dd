"""Server memory (issue 5): resident memory at idle, and after many utterances.

Goals: RSS < 150 MB at idle; flat (within +-5%) after 10,000 utterances. A real
`lipclock serve` on loopback; one WebSocket subscriber stays connected (so every
utterance is streamed); utterances are POSTed 8 at a time. RSS of the server process
is read with psutil after warm-up (idle), after the first --utterances/10 (settled:
caches and the utterance store are full), and at the end.

    .venv/bin/python bench/bench_server_memory.py [--utterances 10000]
"""

from __future__ import annotations

import argparse
import asyncio
import time

import httpx
import psutil
import websockets

from serverutil import running_server

TEXTS = ["Please hold the door.", "The next train leaves at 9:45.",
         "Thank you for visiting the museum today!", "Would you like to hear that again?",
         "Your order number is 1,024.", "Elevators are on the left, past the cafe."]


async def drain(url: str, stop: asyncio.Event) -> int:
    n = 0
    async with websockets.connect(url, max_size=None, compression=None) as ws:
        await ws.recv()
        while not stop.is_set():
            try:
                msg = await asyncio.wait_for(ws.recv(), timeout=0.5)
            except TimeoutError:
                continue
            if isinstance(msg, str) and msg.startswith('{"type":"end"'):
                n += 1
    return n


async def run(addr: str, pid: int, total: int) -> dict[str, float]:
    proc = psutil.Process(pid)
    rss = {}
    stop = asyncio.Event()
    drainer = asyncio.create_task(drain(f"ws://{addr}/ws?channel=mem", stop))
    await asyncio.sleep(0.5)
    async with httpx.AsyncClient(base_url=f"http://{addr}", timeout=60) as http:
        async def speak(i: int) -> None:
            for _ in range(50):
                r = await http.post("/speak", json={"text": TEXTS[i % len(TEXTS)],
                                                    "channel": "mem"})
                if r.status_code != 429:  # channel queue full: wait and retry
                    r.raise_for_status()
                    return
                await asyncio.sleep(0.05)
            raise RuntimeError("channel stayed busy")

        for i in range(24):  # warm-up
            await speak(i)
        await asyncio.sleep(1.0)
        rss["idle"] = proc.memory_info().rss / 2**20
        t0 = time.perf_counter()
        settle = max(1, total // 10)
        for start in range(0, total, 8):
            await asyncio.gather(*(speak(i) for i in range(start, min(total, start + 8))))
            if start <= settle < start + 8:
                await asyncio.sleep(0.5)
                rss["settled"] = proc.memory_info().rss / 2**20
        await asyncio.sleep(2.0)
        rss["end"] = proc.memory_info().rss / 2**20
        rss["seconds"] = time.perf_counter() - t0
    stop.set()
    rss["streamed"] = await drainer
    return rss


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--utterances", type=int, default=10000)
    args = ap.parse_args()
    with running_server() as (addr, proc):
        r = asyncio.run(run(addr, proc.pid, args.utterances))
    print(f"server RSS idle (after warm-up): {r['idle']:.1f} MB (goal < 150 MB)")
    change = 100 * (r["end"] / r["settled"] - 1)
    print(f"after {args.utterances // 10} utterances: {r['settled']:.1f} MB; after "
          f"{args.utterances}: {r['end']:.1f} MB -> change {change:+.1f}% (goal within +-5%)")
    print(f"{args.utterances} utterances in {r['seconds']:.0f} s; the subscriber saw "
          f"{int(r['streamed'])} utterance ends")


if __name__ == "__main__":
    main()
