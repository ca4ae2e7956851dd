"""Behaviour of the mouth models through the public face API (issue 4).

Timelines are built by hand (phones + samples) so these tests pin the face
stage independently of the front end's durations.
"""

from __future__ import annotations

import math
from itertools import pairwise

import numpy as np
import pytest

from lipclock.errors import LipclockError, OutOfRangeError, TableError, UnknownChoiceError
from lipclock.face.models import MOUTH_MODELS, mouth_for
from lipclock.face.visemes import load_phone_map, load_shapes, shapes, visemes_for
from lipclock.speech.timeline import PhoneSpan, Timeline

SR = 16000


def make_timeline(phones: list[tuple[str, float]], sample_rate: int = SR) -> Timeline:
    """phones: (phone, duration_s). Builds contiguous spans from sample 0."""
    spans, t = [], 0
    for ph, dur_s in phones:
        n = max(1, round(dur_s * sample_rate))
        spans.append(PhoneSpan(ph, t, t + n))
        t += n
    return Timeline(sample_rate=sample_rate, phones=tuple(spans))


def mom(scale: float) -> Timeline:
    """'mom mom mom' with durations scaled (smaller = faster speech)."""
    seq = [("pau", 0.2)]
    for _ in range(3):
        seq += [("M", 0.07 * scale), ("AA1", 0.14 * scale), ("M", 0.07 * scale)]
    return make_timeline(seq + [("pau", 0.2)])


def gap_in_phone(track, span) -> float:
    fs = track.frame_samples()
    lo, hi = np.searchsorted(fs, [span.start, span.end])
    hi = max(hi, lo + 1)
    return float(track.measures["lip_gap"][lo:hi].min())


@pytest.mark.parametrize("model", MOUTH_MODELS)
def test_models_give_finite_frames_on_the_sample_clock(model: str) -> None:
    tl = mom(1.0)
    tr = mouth_for(tl, model, rate_hz=100.0)
    assert tr.frames.ndim == 3 and tr.frames.shape[1:] == (len(tr.nodes), 2)
    assert np.isfinite(tr.frames).all()
    for name in ("lip_gap", "width", "jaw"):
        assert tr.measures[name].shape == (tr.frames.shape[0],)
        assert np.isfinite(tr.measures[name]).all()
    assert tr.frame_sample(0) == 0
    assert tr.frame_sample(7) == round(7 * SR / 100.0)
    # frames cover the utterance: the last frame is within one frame of the end
    assert abs(tr.frame_sample(tr.frames.shape[0] - 1) - tl.num_samples) <= SR / 100


def test_slice_returns_frames_whose_sample_is_in_range() -> None:
    tr = mouth_for(mom(1.0), "cosine", rate_hz=60.0)
    part = tr.slice(3000, 9000)
    ks = [k for k in range(tr.frames.shape[0]) if 3000 <= tr.frame_sample(k) < 9000]
    assert part.frames.shape[0] == len(ks)
    np.testing.assert_array_equal(part.frames, tr.frames[ks[0]:ks[-1] + 1])
    marks = tr.to_marks()
    assert len(marks["frames"]) == tr.frames.shape[0]
    assert set(marks["measures"]) >= {"lip_gap", "width", "jaw"}


@pytest.mark.parametrize("scale", [1.0, 0.5])  # 0.5: roughly twice normal speed
def test_spring_closes_bilabials_even_when_fast(scale: float) -> None:
    tl = mom(scale)
    tr = mouth_for(tl, "spring")
    open_gap = float(np.percentile(tr.measures["lip_gap"], 95))
    assert open_gap > 3.0  # the vowels do open the mouth
    for span in tl.phones:
        if span.phone == "M":
            assert gap_in_phone(tr, span) <= 0.1 * open_gap, span


def test_labiodental_reaches_contact_when_fast() -> None:
    seq = [("pau", 0.2)] + [("AA1", 0.07), ("F", 0.04), ("AA1", 0.07), ("V", 0.04)] * 3
    tl = make_timeline(seq + [("pau", 0.2)])
    tr = mouth_for(tl, "spring")
    open_gap = float(np.percentile(tr.measures["lip_gap"], 95))
    contact = shapes()["labiodental"].lip_gap_mm
    for span in tl.phones:
        if span.phone in ("F", "V"):
            assert gap_in_phone(tr, span) <= max(contact + 0.5, 0.25 * open_gap), span


def peak_jaw_on_vowels(model: str, scale: float) -> float:
    tl = mom(scale)
    tr = mouth_for(tl, model)
    fs = tr.frame_samples()
    peaks = []
    for span in tl.phones:
        if span.phone == "AA1":
            lo, hi = np.searchsorted(fs, [span.start, span.end])
            peaks.append(float(tr.measures["jaw"][lo:max(hi, lo + 1)].max()))
    return float(np.mean(peaks))


def test_spring_excursions_shrink_with_rate_but_cosine_does_not() -> None:
    spring_drop = 1 - peak_jaw_on_vowels("spring", 0.4) / peak_jaw_on_vowels("spring", 1.0)
    cosine_drop = 1 - peak_jaw_on_vowels("cosine", 0.4) / peak_jaw_on_vowels("cosine", 1.0)
    assert spring_drop > 0.10
    assert abs(cosine_drop) < 0.05


def test_spring_accelerates_and_decelerates() -> None:
    """Velocity of the jaw rises smoothly from rest rather than jumping."""
    tl = make_timeline([("pau", 0.3), ("AA1", 0.4), ("pau", 0.3)])
    tr = mouth_for(tl, "spring", rate_hz=200.0)
    v = np.diff(tr.measures["jaw"].astype(np.float64)) * 200.0
    k = int(np.argmax(np.abs(v)))
    assert 0 < k < len(v) - 1
    assert abs(v[k - 1]) < abs(v[k]) and abs(v[k + 1]) < abs(v[k])
    assert abs(v[k]) > 0  # it moved at all


def test_unknown_model_lists_the_choices() -> None:
    with pytest.raises(UnknownChoiceError) as e:
        mouth_for(mom(1.0), "wobbly")
    for name in MOUTH_MODELS:
        assert name in str(e.value)


def test_unstable_spring_parameters_are_rejected_with_range() -> None:
    with pytest.raises(OutOfRangeError) as e:
        # a 10 ms step is far too coarse for a very stiff closure spring
        mouth_for(mom(1.0), "spring",
                  params={"integration.step_s": 0.01, "closure.stiffness": 1e6})
    assert "allowed" in str(e.value)
    with pytest.raises(LipclockError):  # a typed error, never a crash
        mouth_for(mom(1.0), "spring", params={"integration.step_s": math.inf})
    with pytest.raises(UnknownChoiceError):
        mouth_for(mom(1.0), "spring", params={"no_such_knob": 1.0})


def test_visemes_cover_the_timeline() -> None:
    tl = mom(1.0)
    ev = visemes_for(tl)
    assert ev[0].start == 0 and ev[-1].end == tl.num_samples
    assert all(a.end == b.start and a.viseme != b.viseme for a, b in pairwise(ev))


def test_bad_shape_table_fails_with_file_line(tmp_path) -> None:
    p = tmp_path / "visemes.tsv"
    p.write_text("# comment\nrest\t0\t50\t0\t2\nopen\tnan\t50\t0\t10\n")
    with pytest.raises(TableError) as e:
        load_shapes(p)
    assert f"{p}:3" in str(e.value)


def test_phone_map_with_unknown_phone_fails_with_file_line(tmp_path) -> None:
    p = tmp_path / "map.tsv"
    p.write_text("pau\trest\nQX\trest\n")
    with pytest.raises(TableError) as e:
        load_phone_map(p, shapes())
    assert f"{p}:2" in str(e.value) and "QX" in str(e.value)


def test_phone_map_with_unknown_viseme_fails_with_file_line(tmp_path) -> None:
    p = tmp_path / "map.tsv"
    p.write_text("pau\trest\nP\tkiss\n")
    with pytest.raises(TableError) as e:
        load_phone_map(p, shapes())
    assert f"{p}:2" in str(e.value)


def test_no_model_exceeds_the_documented_node_speed_limit() -> None:
    from lipclock.face.models import MAX_NODE_SPEED_MM_S
    from lipclock.speech.frontend import text_to_timeline

    tl = text_to_timeline("Pop the big map, mom; we buy five bobbing apples.", rate_wpm=450)
    for name in MOUTH_MODELS:
        track = mouth_for(tl, name, rate_hz=100.0)
        step = np.linalg.norm(np.diff(track.frames, axis=0), axis=2)
        assert step.max() * 100.0 <= MAX_NODE_SPEED_MM_S * 1.001, name
