"""Helpers shared by the real-browser tests and bench/: the Chromium binary, its flags, and
a real `lipclock serve` process on a free port."""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
HAVE_CHROMIUM = Path(CHROMIUM).exists()
ARTIFACTS = ROOT / "artifacts" / "screenshots"
FACE_ARTIFACTS = ROOT / "test-artifacts"   # the face's screenshots, for people to look at
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_server(env: dict[str, str] | None = None, port: int | None = None):
    """Start `lipclock serve` as a user would; wait for /healthz (a cold first start on a
    busy machine can take a while), and never leave the process behind on failure."""
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
