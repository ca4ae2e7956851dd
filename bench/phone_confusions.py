"""Which phones the listener mishears: per-phone recognition, lipclock beside its peers.

A diagnostic for intelligibility work, not a goal figure. Every system speaks the
same sentences (bench/intelligibility/sentences.txt); PocketSphinx decodes each in
*allphone* mode (its phone language model, no words), and the decoded phones are
aligned with the reference phones by edit distance. The reference is lipclock's own
front end (stress dropped, pauses removed) for every system, so peers are scored
against the same pronunciations; where a peer pronounces a word differently, all
systems' numbers for that phone sink together.

Prints, per reference phone: how often it occurs, the percentage each system got
right, and lipclock's most common confusions (``-`` is a deletion).

    .venv/bin/python bench/phone_confusions.py [--systems lipclock:adult-low,espeak-klatt2]
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from collections import Counter, defaultdict
from multiprocessing import Pool
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))

import bench_intelligibility as bi  # noqa: E402

_DEC: list = []


def _init() -> None:
    """bench_intelligibility's worker set-up (its systems) plus an allphone decoder."""
    import pocketsphinx

    bi._worker_init()
    model = Path(pocketsphinx.get_model_path()) / "en-us" / "en-us-phone.lm.bin"
    _DEC.append(pocketsphinx.Decoder(samprate=bi.LISTEN_RATE, allphone=str(model),
                                     lw=2.0, beam=1e-20, pbeam=1e-20, loglevel="FATAL"))


def reference_phones(text: str) -> list[str]:
    import lipclock

    prepared = lipclock.prepare(text, voice="adult-low")  # phones only: no audio needed
    return [re.sub(r"\d", "", p.phone) for p in prepared.phones if p.phone not in ("pau", "sil")]


def _job(job: tuple[str, str]) -> tuple[str, str, list[str]]:
    system, text = job
    with tempfile.TemporaryDirectory(prefix="phones-") as tmp:
        samples = bi._SYSTEMS[system](text, Path(tmp))
    d = _DEC[0]
    d.start_utt()
    d.process_raw(bi.listener_input(samples, text).tobytes(), full_utt=True)
    d.end_utt()
    phones = [s.word for s in d.seg() if s.word not in ("SIL", "+NSN+", "+SPN+")
              and not s.word.startswith("+")]
    return system, text, phones


def align(ref: list[str], hyp: list[str]) -> list[tuple[str, str]]:
    """(reference phone, what was heard or '-') for every reference phone."""
    n, m = len(ref), len(hyp)
    cost = np.zeros((n + 1, m + 1), dtype=np.int32)
    cost[:, 0] = np.arange(n + 1)
    cost[0, :] = np.arange(m + 1)
    for i in range(1, n + 1):
        for j in range(1, m + 1):
            cost[i, j] = min(cost[i - 1, j] + 1, cost[i, j - 1] + 1,
                             cost[i - 1, j - 1] + (ref[i - 1] != hyp[j - 1]))
    pairs: list[tuple[str, str]] = []
    i, j = n, m
    while i > 0:
        if j > 0 and cost[i, j] == cost[i - 1, j - 1] + (ref[i - 1] != hyp[j - 1]):
            pairs.append((ref[i - 1], hyp[j - 1]))
            i, j = i - 1, j - 1
        elif cost[i, j] == cost[i - 1, j] + 1:
            pairs.append((ref[i - 1], "-"))
            i -= 1
        else:
            j -= 1
    return pairs[::-1]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--systems", default="lipclock:adult-low,lipclock:adult-high,"
                    "espeak-klatt2,flite-kal,flite-slt")
    ap.add_argument("--workers", type=int, default=2, choices=(1, 2))
    args = ap.parse_args(argv)
    systems = args.systems.split(",")
    sentences = bi.read_sentences()
    refs = {s: reference_phones(s) for s in sentences}
    with Pool(args.workers, initializer=_init) as pool:
        results = pool.map(_job, [(sy, s) for sy in systems for s in sentences])
    right: dict[str, Counter] = defaultdict(Counter)
    total: Counter = Counter()
    confusions: dict[str, Counter] = defaultdict(Counter)
    for system, text, hyp in results:
        for r, h in align(refs[text], hyp):
            if system == systems[0]:
                total[r] += 1
                if h != r:
                    confusions[r][h] += 1
            right[system][r] += h == r
    names = [s.replace("lipclock:", "") for s in systems]
    print(f"{'phone':6}{'n':>5}" + "".join(f"{n:>14}" for n in names) + "   confusions "
          f"({names[0]})")
    for ph, n in sorted(total.items(), key=lambda kv: -kv[1]):
        cells = "".join(f"{100 * right[s][ph] / n:13.0f}%" for s in systems)
        top = ", ".join(f"{h}:{c}" for h, c in confusions[ph].most_common(4))
        print(f"{ph:6}{n:5d}{cells}   {top}")
    n_all = sum(total.values())
    print(f"{'all':6}{n_all:5d}" + "".join(
        f"{100 * sum(right[s].values()) / n_all:13.1f}%" for s in systems))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
