"""Synthesis speed beside eSpeak-NG, timed in the same run.

* Throughput: audio seconds per CPU second, in-process, front end included,
  after warm-up (median of runs), on bench/data/prose.txt. Peer: the
  ``espeak-ng`` process on the same text writing a WAV, CPU time of the whole
  process (RUSAGE_CHILDREN), audio length from its WAV. Goal: >= eSpeak-NG.
* Time to the first audio chunk of a 20-word sentence after warm-up
  (``prepare()`` + first ``audio_chunks()`` item; wall time, median). Goal: <= 15 ms.
* Cold start of ``lipclock say`` (new process, wall time, median of 3). Goal: < 2 s.

    .venv/bin/python bench/bench_speed.py [--runs 5] [--voice adult-low]
"""

from __future__ import annotations

import argparse
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import wave
from pathlib import Path

import lipclock

HERE = Path(__file__).parent
SENTENCE_20 = ("Please remember that the north elevators are closed for repairs today, so use "
               "the stairs near the main entrance instead.")


def ours(text: str, runs: int, voice: str) -> tuple[float, float]:
    lipclock.synthesize("Warm up the synthesizer and the lexicon.", voice=voice)
    rates, audio_s = [], 0.0
    for _ in range(runs):
        t0 = time.process_time()
        utt = lipclock.synthesize(text, voice=voice, settings=lipclock.Settings(
            max_text_chars=len(text) + 1))
        cpu = time.process_time() - t0
        audio_s = utt.duration_s
        rates.append(audio_s / cpu)
    return statistics.median(rates), audio_s


def espeak(text: str, runs: int) -> float | None:
    exe = shutil.which("espeak-ng")
    if not exe:
        return None
    tmp = Path(tempfile.mkdtemp())
    (tmp / "t.txt").write_text(text)
    rates = []
    for _ in range(runs):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([exe, "-w", str(tmp / "o.wav"), "-f", str(tmp / "t.txt")], check=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
        with wave.open(str(tmp / "o.wav")) as w:
            rates.append(w.getnframes() / w.getframerate() / cpu)
    return statistics.median(rates)


def first_chunk_ms(runs: int, voice: str) -> float:
    lipclock.prepare(SENTENCE_20, voice=voice)
    times = []
    for _ in range(runs * 4):
        t0 = time.perf_counter()
        prep = lipclock.prepare(SENTENCE_20, voice=voice)
        next(iter(prep.audio_chunks()))
        times.append(1000 * (time.perf_counter() - t0))
    return statistics.median(times)


def cold_start_s() -> float:
    exe = Path(sys.executable).with_name("lipclock")
    times = []
    out = Path(tempfile.mkdtemp()) / "c.wav"
    for _ in range(3):
        t0 = time.perf_counter()
        subprocess.run([str(exe), "say", "Hello from a cold start.", "-o", str(out)], check=True)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--voice", default="adult-low")
    args = ap.parse_args()
    text = (HERE / "data" / "prose.txt").read_text()
    rate, audio_s = ours(text, args.runs, args.voice)
    peer = espeak(text, args.runs)
    print(f"text: {len(text.split())} words, {audio_s:.1f} s of lipclock audio")
    print(f"{'system':<36}{'x real time (audio s / CPU s)':>30}")
    print(f"{'lipclock in-process (front end incl.)':<36}{rate:>30.0f}")
    if peer:
        print(f"{'espeak-ng whole process':<36}{peer:>30.0f}")
        print(f"ratio lipclock/espeak-ng: {rate / peer:.2f} (goal >= 1.00)")
    fc = first_chunk_ms(args.runs, args.voice)
    print(f"first audio chunk, 20-word sentence: {fc:.1f} ms median (goal <= 15 ms)")
    print(f"cold start of `lipclock say`: {cold_start_s():.2f} s median of 3 (goal < 2 s)")


if __name__ == "__main__":
    main()
