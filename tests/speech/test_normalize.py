"""Normalisation: golden INPUT/OUTPUT cases (flite-style), typed errors, hostile input."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lipclock.errors import EmptyTextError, LipclockError, TextTooLongError
from lipclock.speech.normalize import normalize, tokens_to_text
from lipclock.speech.tokens import BreakToken, WordToken

GOLDEN = Path(__file__).parent / "golden" / "normalize.tsv"


def golden_cases() -> list[tuple[str, str]]:
    cases = []
    for line in GOLDEN.read_text(encoding="utf-8").splitlines():
        if line.startswith("#") or not line.strip():
            continue
        inp, out = line.split("\t")
        cases.append((inp, out))
    return cases


@pytest.mark.parametrize("text,expected", golden_cases())
def test_golden(text, expected):
    assert tokens_to_text(normalize(text)) == expected


def test_golden_file_is_substantial():
    assert len(golden_cases()) >= 100


def test_acronyms_use_the_lexicon_predicate():
    # with a lexicon that knows "nasa", NASA is a word; with none it still reads as one
    toks = normalize("NASA and FBI", is_word=lambda w: w == "nasa")
    assert tokens_to_text(toks) == "nasa and f. b. i."


@pytest.mark.parametrize("text", ["", "   ", "\n\t  \r\n"])
def test_empty_text_is_a_typed_error(text):
    with pytest.raises(EmptyTextError) as exc:
        normalize(text)
    assert "empty" in exc.value.reason


@pytest.mark.parametrize("text", ["!!!", "🙂🙂", "(( ))", "---"])
def test_nothing_speakable_is_a_typed_error(text):
    with pytest.raises(EmptyTextError):
        normalize(text)


def test_over_limit_is_rejected_not_truncated():
    with pytest.raises(TextTooLongError) as exc:
        normalize("a" * 5001)
    assert exc.value.limit == 5000 and exc.value.length == 5001
    assert len(normalize("a " * 2500, max_chars=5000)) == 2500
    with pytest.raises(TextTooLongError):
        normalize("hello there", max_chars=5)


def test_hostile_inputs_are_bounded():
    commas = normalize("a" + "," * 10000, max_chars=20000)
    assert isinstance(commas[0], WordToken) and len(commas) == 10001
    digits = normalize("1" * 1000, max_chars=2000)
    assert len(digits) == 1000 and all(t.text == "one" for t in digits)
    long_word = normalize("x" * 100000, max_chars=200000)
    assert 1 <= len(long_word) <= 20
    ctrl = normalize("hel\x00lo\x07 wor\x1bld\u200b")
    assert all(re.fullmatch(r"[a-z']+", t.text) for t in ctrl if isinstance(t, WordToken))


_TEXT = st.text(
    alphabet=st.one_of(
        st.characters(codec="utf-8"),
        st.sampled_from(list("0123456789$£€%:.,;!?-()'\"@/ abcXYZ\n\t")),
    ),
    max_size=300,
)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_TEXT)
def test_property_any_text_gives_tokens_or_a_typed_error(text):
    try:
        toks = normalize(text, max_chars=1000)
    except LipclockError:
        return
    assert toks
    assert any(isinstance(t, WordToken) for t in toks)
    for t in toks:
        if isinstance(t, WordToken):
            assert re.fullmatch(r"[a-z']+", t.text), t
            assert len(t.text) <= 40
        else:
            assert isinstance(t, BreakToken)
    # bounded expansion: never more than a few tokens per input character
    assert len(toks) <= 8 * len(text) + 8


@settings(max_examples=100, deadline=None)
@given(st.integers(min_value=-10**15, max_value=10**15))
def test_property_integers_read_as_words(n):
    toks = normalize(str(n))
    assert all(isinstance(t, WordToken) for t in toks)
    assert toks[0].text == ("minus" if n < 0 else toks[0].text)
