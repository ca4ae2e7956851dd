"""Start a real `lipclock serve` process on a free loopback port, and the headless Chromium
flags; shared by the benches and the browser tests (tests/client/browser_util.py)."""

from __future__ import annotations

import asyncio
import contextlib
import os
import random
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


# Debian's chromium, headless with software rendering, as the issue asks
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu",
                 "--disable-background-networking", "--disable-component-update",
                 "--disable-sync", "--no-first-run"]


def start_server(env: dict[str, str] | None = None,
                 port: int | None = None) -> tuple[str, subprocess.Popen]:
    """Start `lipclock serve` as a user would; wait for /healthz (a cold first start on a
    busy machine can take a while), and never leave the process behind on failure.
    Returns the base URL and the process; the caller terminates it."""
    port = port or free_port()
    exe = Path(sys.executable).with_name("lipclock")
    log = tempfile.TemporaryFile()  # a file, not a pipe: a full pipe would block the server
    proc = subprocess.Popen([str(exe), "serve", "--port", str(port)],
                            env={**os.environ, **(env or {})},
                            stdout=subprocess.DEVNULL, stderr=log)
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        try:
            urllib.request.urlopen(url + "/healthz", timeout=1)
            log.close()  # the server keeps its own descriptor
            return url, proc
        except OSError:
            time.sleep(0.1)
    proc.kill()
    proc.wait(timeout=10)
    with log:
        log.seek(0)
        tail = log.read().decode(errors="replace")[-2000:]
    raise RuntimeError(f"server did not start (exit {proc.returncode}): {tail}")


@contextlib.contextmanager
def running_server(env: dict[str, str] | None = None) -> Iterator[tuple[str, subprocess.Popen]]:
    """start_server() as a context manager yielding "127.0.0.1:PORT" and the process."""
    url, proc = start_server(env)
    try:
        yield url.removeprefix("http://"), proc
    finally:
        proc.terminate()
        proc.wait(timeout=15)


def percentile(xs: list[float], q: float) -> float:
    s = sorted(xs)
    return s[min(len(s) - 1, max(0, round(q / 100 * (len(s) - 1))))]


async def jitter_proxy(listen_port: int, target_port: int, lo_s: float, hi_s: float,
                       rng: random.Random) -> asyncio.AbstractServer:
    async def pipe(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        queue: asyncio.Queue[tuple[float, bytes]] = asyncio.Queue()
        last_due = 0.0

        async def deliver() -> None:
            while True:
                due, data = await queue.get()
                if not data:
                    writer.close()
                    return
                await asyncio.sleep(max(0.0, due - time.monotonic()))
                writer.write(data)
                await writer.drain()

        task = asyncio.create_task(deliver())
        while True:
            data = await reader.read(65536)
            last_due = max(last_due, time.monotonic() + rng.uniform(lo_s, hi_s))
            await queue.put((last_due, data))
            if not data:
                break
        await task

    async def handle(cr: asyncio.StreamReader, cw: asyncio.StreamWriter) -> None:
        try:
            sr, sw = await asyncio.open_connection("127.0.0.1", target_port)
            pipes = [asyncio.create_task(pipe(cr, sw)), asyncio.create_task(pipe(sr, cw))]
            try:
                await asyncio.wait(pipes)
            finally:
                for task in pipes:
                    task.cancel()
                await asyncio.gather(*pipes, return_exceptions=True)
                sw.close()
        except (asyncio.CancelledError, OSError):
            pass  # shutting down, or one end went away: end this connection quietly
        finally:
            cw.close()

    return await asyncio.start_server(handle, "127.0.0.1", listen_port)


@contextlib.contextmanager
def jitter_proxy_thread(target_port: int, lo_s: float, hi_s: float,
                        seed: int = 7) -> Iterator[int]:
    """A jitter proxy on its own event loop thread (for sync callers such as Playwright);
    yields the port to connect to instead of target_port."""
    port = free_port()
    loop = asyncio.new_event_loop()

    async def main() -> asyncio.AbstractServer:
        return await jitter_proxy(port, target_port, lo_s, hi_s, random.Random(seed))

    thread = threading.Thread(target=loop.run_forever, daemon=True)
    thread.start()
    fut = asyncio.run_coroutine_threadsafe(main(), loop)
    server = fut.result(timeout=10)
    try:
        yield port
    finally:
        async def shutdown() -> None:
            server.close()
            for _ in range(5):  # cancelling a connection can leave its pipes to finish
                tasks = [t for t in asyncio.all_tasks() if t is not asyncio.current_task()]
                if not tasks:
                    break
                for task in tasks:
                    task.cancel()
                await asyncio.gather(*tasks, return_exceptions=True)

        asyncio.run_coroutine_threadsafe(shutdown(), loop).result(timeout=10)
        loop.call_soon_threadsafe(loop.stop)
        thread.join(timeout=10)
        loop.close()
