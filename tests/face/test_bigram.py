"""Bigram blend-curve model (Xu et al. 2013): tables, overrides and behaviour."""

from __future__ import annotations

import numpy as np
import pytest

from lipclock.errors import OutOfRangeError, TableError, UnknownChoiceError
from lipclock.face.bigram import default_tables, load_classes, load_curves
from lipclock.face.models import mouth_for
from lipclock.speech.timeline import PhoneSpan, Timeline

SR = 16000


def tl_of(seq: list[tuple[str, float]]) -> Timeline:
    spans, t = [], 0
    for ph, dur_s in seq:
        n = round(dur_s * SR)
        spans.append(PhoneSpan(ph, t, t + n))
        t += n
    return Timeline(sample_rate=SR, phones=tuple(spans))


def test_default_set_is_21_classes_with_every_bigram() -> None:
    classes, curves, constraints = default_tables()
    assert len(classes) == 21
    assert all((a, b) in curves for a in classes for b in classes)
    assert ("closed", "open") in constraints


def test_bigram_closes_mom_and_opens_the_vowel() -> None:
    tl = tl_of([("pau", 0.2), ("M", 0.05), ("AA1", 0.1), ("M", 0.05), ("pau", 0.2)])
    tr = mouth_for(tl, "bigram")
    gap = tr.measures["lip_gap"]
    fs = tr.frame_samples()
    assert np.isfinite(tr.frames).all()
    for span in tl.phones[1:4]:
        lo, hi = np.searchsorted(fs, [span.start, span.end])
        seg = gap[lo:hi]
        if span.phone == "M":
            assert seg.min() <= 0.1 * gap.max()
        else:
            assert seg.max() > 5.0


def test_speed_limit_bounds_the_change_per_frame() -> None:
    tl = tl_of([("pau", 0.2)] + [("M", 0.04), ("AA1", 0.06)] * 6 + [("pau", 0.2)])
    slow = mouth_for(tl, "bigram", params={"max_rate_per_s": 4.0})
    fast = mouth_for(tl, "bigram", params={"max_rate_per_s": 100.0})
    def jump(tr):  # noqa: E306
        return float(np.abs(np.diff(tr.measures["jaw"])).max())
    assert jump(slow) < jump(fast)


def test_character_override_changes_the_motion_and_unknown_is_rejected() -> None:
    tl = tl_of([("pau", 0.2), ("AA1", 0.3), ("pau", 0.2)])
    base_jaw = mouth_for(tl, "bigram").measures["jaw"].max()
    lazy_jaw = mouth_for(tl, "bigram", params={"character": "mumbler"}).measures["jaw"].max()
    assert lazy_jaw < base_jaw
    with pytest.raises(UnknownChoiceError):
        mouth_for(tl, "bigram", params={"character": "nobody"})
    with pytest.raises(OutOfRangeError):
        mouth_for(tl, "bigram", params={"max_rate_per_s": float("nan")})


def test_curve_file_errors_name_file_and_line(tmp_path) -> None:
    classes, _, _ = default_tables()
    bad = {
        "unknown class": "sil\tXX\trest\t0:1 1:1\n",
        "unknown pose": "sil\tPBM\tpout\t0:1 1:1\n",
        "non-finite": "sil\tPBM\trest\t0:1 0.5:nan 1:0\n",
        "knots": "sil\tPBM\trest\t0.2:1 1:0\n",
    }
    for why, row in bad.items():
        p = tmp_path / "c.tsv"
        p.write_text("# header\n" + row)
        with pytest.raises(TableError) as e:
            load_curves(p, classes)
        assert f"{p}:2" in str(e.value), why


def test_class_table_rejects_unknown_phone(tmp_path) -> None:
    p = tmp_path / "classes.tsv"
    p.write_text("sil\trest\tpau\nPBM\tclosed\tP B QQ\n")
    with pytest.raises(TableError) as e:
        load_classes(p)
    assert f"{p}:2" in str(e.value) and "QQ" in str(e.value)
