"""The Timeline contract: immutable, tiled phones, integer samples, F0 lookup."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lipclock.speech.phoneset import base, info, is_valid, phones, stress
from lipclock.speech.timeline import F0Point, PhoneSpan, Timeline


def test_timeline_is_immutable_and_validated():
    t = Timeline(16000, (PhoneSpan("pau", 0, 100), PhoneSpan("AA1", 100, 900, 0)),
                 f0=(F0Point(0, 100.0), F0Point(900, 200.0)))
    with pytest.raises(dataclasses.FrozenInstanceError):
        t.sample_rate = 8000  # type: ignore[misc]
    assert t.num_samples == 900 and t.duration_s == pytest.approx(900 / 16000)
    assert np.allclose(t.f0_at(np.array([0, 450, 900, 5000])), [100, 150, 200, 200])
    assert t.phone_index_at(0) == 0 and t.phone_index_at(100) == 1 and t.phone_index_at(10**6) == 1


def test_gaps_and_overlaps_are_rejected():
    with pytest.raises(ValueError):
        Timeline(16000, (PhoneSpan("pau", 0, 100), PhoneSpan("AA1", 120, 900)))
    with pytest.raises(ValueError):
        Timeline(16000, (PhoneSpan("pau", 0, 100),), f0=(F0Point(50, 1.0), F0Point(10, 1.0)))


def test_phoneset_helpers():
    assert len(phones()) == 40
    assert base("AH0") == "AH" and stress("AH0") == 0 and stress("S") is None
    assert info("IY1").is_vowel and info("S").is_consonant and not info("pau").is_consonant
    assert is_valid("AA1") and not is_valid("AA") and not is_valid("S1") and not is_valid("QQ")
