"""Letter-to-sound: a joint-sequence (graphone) n-gram model (Bisani & Ney 2008).

Each letter emits a *chunk* of 0, 1 or 2 phones (stress digits included, so
stress is predicted jointly); a word is a sequence of graphones
``letter:chunk``. ``scripts/build_lts.py`` aligns CMUdict by EM, counts graphone
n-grams and stores interpolated absolute-discounting estimates in
``data/lts_model.npz``:

    P(g | h) = alpha(h, g) + gamma(h) * P(g | h[1:])

Decoding is a beam search over the graphones allowed for each letter. The model
is small, fast and deterministic; nothing is downloaded at run time.
"""

from __future__ import annotations

import random
from collections.abc import Iterable, Sequence
from functools import cache
from pathlib import Path

import numpy as np

from ..tables import package_file

SPLIT_SEED = 20260  # fixed: the held-out 10% must be the same for build and bench
HELDOUT_FRACTION = 0.10
BOS, EOS = 0, 1  # graphone ids of the word-boundary tokens
BEAM = 24
_MASK = (1 << 61) - 1


def heldout_split(words: Iterable[str], seed: int = SPLIT_SEED,
                  fraction: float = HELDOUT_FRACTION) -> tuple[list[str], list[str]]:
    """Deterministic (train, heldout) split of a word list."""
    ws = sorted(set(words))
    random.Random(seed).shuffle(ws)
    cut = int(len(ws) * (1.0 - fraction))
    return sorted(ws[:cut]), sorted(ws[cut:])


def ngram_key(ids: Sequence[int]) -> int:
    """Deterministic 61-bit hash of a graphone-id tuple (polynomial, stable across runs)."""
    h = 1469598103934665603 & _MASK
    for i in ids:
        h = ((h * _PRIME) ^ (i + 7)) & _MASK
    return h


_PRIME = 1099511628211


class LtsModel:
    """Graphone n-gram tables as sorted key arrays; decoding is vectorised per letter."""

    def __init__(self, order: int, letters: list[str], chunks: list[tuple[str, ...]],
                 alpha_keys: np.ndarray, alpha_vals: np.ndarray, gamma_keys: np.ndarray,
                 gamma_vals: np.ndarray, unigram: np.ndarray, candidates: np.ndarray) -> None:
        self.order = order
        self.letters = letters
        self.chunks = chunks
        ia, ig = np.argsort(alpha_keys), np.argsort(gamma_keys)
        self.alpha_keys = alpha_keys[ia].astype(np.uint64)
        self.alpha_vals = alpha_vals[ia].astype(np.float32)
        self.gamma_keys = gamma_keys[ig].astype(np.uint64)
        self.gamma_vals = gamma_vals[ig].astype(np.float32)
        self.unigram = unigram.astype(np.float64)
        self.by_letter: dict[str, np.ndarray] = {}
        for gid in candidates.tolist():
            self.by_letter.setdefault(letters[gid], []).append(gid)  # type: ignore[arg-type]
        self.by_letter = {k: np.array(v, dtype=np.int64) for k, v in self.by_letter.items()}

    @property
    def n_ngrams(self) -> int:
        return int(len(self.alpha_keys))

    @classmethod
    def load(cls, path: Path) -> LtsModel:
        z = np.load(path, allow_pickle=False)
        letters = [str(x) for x in z["letters"]]
        chunks = [tuple(str(x).split()) for x in z["chunks"]]
        uni = np.full(len(letters), 1e-7)
        uni[z["uni_ids"]] = z["uni_vals"]
        return cls(int(z["order"]), letters, chunks, z["alpha_keys"], z["alpha_vals"],
                   z["gamma_keys"], z["gamma_vals"], uni, z["cand_ids"])

    def _lookup(self, keys: np.ndarray, table: np.ndarray, vals: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
        idx = np.searchsorted(table, keys)
        idx = np.minimum(idx, len(table) - 1)
        found = table[idx] == keys
        return found, np.where(found, vals[idx], 0.0)

    def _probs(self, hkeys: np.ndarray, hvalid: np.ndarray, cand: np.ndarray) -> np.ndarray:
        """P(cand | history) for each beam entry: (B, C)."""
        n_b, n_k = hkeys.shape
        g = (cand.astype(np.uint64) + np.uint64(7))[None, None, :]
        with np.errstate(over="ignore"):
            akeys = ((hkeys[:, :, None] * np.uint64(_PRIME)) ^ g) & np.uint64(_MASK)
        _, alpha = self._lookup(akeys.ravel(), self.alpha_keys, self.alpha_vals)
        alpha = alpha.reshape(n_b, n_k, len(cand))
        gfound, gamma = self._lookup(hkeys.ravel(), self.gamma_keys, self.gamma_vals)
        gfound = gfound.reshape(n_b, n_k) & hvalid
        gamma = gamma.reshape(n_b, n_k)
        p = np.repeat(self.unigram[cand][None, :], n_b, axis=0)
        alive = np.ones(n_b, dtype=bool)
        for k in range(n_k):  # shortest history first
            alive &= gfound[:, k]
            p = np.where(alive[:, None], alpha[:, k, :] + gamma[:, k, None] * p, p)
        return p

    def predict(self, word: str) -> tuple[str, ...]:
        letters = [c for c in word.lower() if c in self.by_letter]
        if not letters:
            return ()
        n = self.order - 1
        # a beam entry: (score, history ids (<= n), path ids)
        beams: list[tuple[float, tuple[int, ...], tuple[int, ...]]] = [(0.0, (BOS,), ())]
        for step in range(len(letters) + 1):
            cand = self.by_letter[letters[step]] if step < len(letters) else \
                np.array([EOS], dtype=np.int64)
            hk = np.zeros((len(beams), n), dtype=np.uint64)
            hv = np.zeros((len(beams), n), dtype=bool)
            for b, (_, hist, _) in enumerate(beams):
                for k in range(len(hist)):  # suffixes of length 1..len(hist)
                    hk[b, k] = ngram_key(hist[len(hist) - k - 1:])
                    hv[b, k] = True
            p = self._probs(hk, hv, cand)
            scores = np.array([b[0] for b in beams])[:, None] + np.log(np.maximum(p, 1e-30))
            if step == len(letters):
                best = int(np.argmax(scores[:, 0]))
                path = beams[best][2]
                break
            flat = np.argsort(-scores, axis=None)[: BEAM * 2]
            nxt: list[tuple[float, tuple[int, ...], tuple[int, ...]]] = []
            seen: set[tuple[int, ...]] = set()
            for f in flat.tolist():
                b, c = divmod(f, len(cand))
                _, hist, pth = beams[b]
                g = int(cand[c])
                h2 = (*hist, g)[-n:]
                if h2 in seen:
                    continue
                seen.add(h2)
                nxt.append((float(scores[b, c]), h2, (*pth, g)))
                if len(nxt) >= BEAM:
                    break
            beams = nxt
        phones: list[str] = []
        for gid in path:
            phones.extend(self.chunks[gid])
        return _fix_stress(tuple(phones))


def _fix_stress(phones: tuple[str, ...]) -> tuple[str, ...]:
    """Exactly one primary stress per word (the first one the model put, else the first vowel)."""
    out = list(phones)
    vowels = [i for i, p in enumerate(out) if p[-1:].isdigit()]
    primaries = [i for i in vowels if out[i].endswith("1")]
    if vowels and not primaries:
        i = vowels[0]
        out[i] = out[i][:-1] + "1"
    for i in primaries[1:]:
        out[i] = out[i][:-1] + "2"
    return tuple(out)


@cache
def default_model() -> LtsModel:
    return LtsModel.load(package_file("lipclock.speech", "data/lts_model.npz"))


def lts_predict(word: str) -> tuple[str, ...]:
    """Phones for a word not in any lexicon (a-z and apostrophes; others ignored)."""
    return default_model().predict(word) or ("AH0",)
