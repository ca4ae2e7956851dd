"""Letter-to-sound accuracy on CMUdict words held out from the model's training data.

The held-out set is ``lts.heldout_split`` (fixed seed, 10%): the build script
(scripts/build_lts.py) never sees it. Scores ignore stress:

* word accuracy: predicted phone string == CMUdict's first pronunciation;
* phone error rate: Levenshtein distance / reference phones, summed over words.

A naive rule baseline (one phone per letter, digraphs ignored) is printed beside it.
Goals (issue 2): word accuracy >= 70%, phone error rate <= 8%.
Published: joint-sequence and neural G2P reach ~75-80% word accuracy on CMUdict.

    .venv/bin/python bench/bench_lts.py [--limit N] [--model PATH]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))

from build_lts import load_cmudict  # noqa: E402

from lipclock.speech.lts import LtsModel, default_model, heldout_split  # noqa: E402

_NAIVE = {
    "a": "AE", "b": "B", "c": "K", "d": "D", "e": "EH", "f": "F", "g": "G", "h": "HH",
    "i": "IH", "j": "JH", "k": "K", "l": "L", "m": "M", "n": "N", "o": "AA", "p": "P",
    "q": "K", "r": "R", "s": "S", "t": "T", "u": "AH", "v": "V", "w": "W", "x": "K S",
    "y": "Y", "z": "Z",
}


def naive(word: str) -> list[str]:
    out: list[str] = []
    for c in word:
        for p in _NAIVE.get(c, "").split():
            if not out or out[-1] != p:
                out.append(p)
    return out


def edit_distance(a: list[str], b: list[str]) -> int:
    prev = list(range(len(b) + 1))
    for i, x in enumerate(a, 1):
        cur = [i] + [0] * len(b)
        for j, y in enumerate(b, 1):
            cur[j] = min(prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (x != y))
        prev = cur
    return prev[-1]


def score(pred_fn, words: list[str], lex: dict) -> tuple[float, float, float]:
    right = errs = total = 0
    t0 = time.process_time()
    for w in words:
        ref = [p.rstrip("012") for p in lex[w]]
        hyp = [p.rstrip("012") for p in pred_fn(w)]
        right += hyp == ref
        errs += edit_distance(hyp, ref)
        total += len(ref)
    dt = time.process_time() - t0
    return right / len(words), errs / total, len(words) / dt


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limit", type=int, default=0, help="score only the first N held-out words")
    ap.add_argument("--model", type=Path, default=None)
    args = ap.parse_args()
    lex = load_cmudict()
    _, heldout = heldout_split(lex)
    words = heldout[: args.limit] if args.limit else heldout
    model = LtsModel.load(args.model) if args.model else default_model()
    print(f"held-out CMUdict words: {len(words)} of {len(heldout)} (seeded 10% split); "
          f"model order {model.order}, {model.n_ngrams} n-grams")
    print(f"{'system':<34}{'word acc':>10}{'phone err':>11}{'words/s':>10}")
    for name, fn in (("naive one-phone-per-letter rules", naive),
                     ("lipclock joint-sequence LTS", model.predict)):
        acc, per, wps = score(fn, words, lex)
        print(f"{name:<34}{100 * acc:>9.1f}%{100 * per:>10.1f}%{wps:>10.0f}")
    print("goals: word accuracy >= 70%, phone error rate <= 8%; "
          "published joint-sequence/neural G2P on CMUdict: ~75-80% word accuracy")
    _ = os  # keep import order stable


if __name__ == "__main__":
    main()
