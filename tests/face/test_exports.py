"""Exports: Oculus 15, Azure 22, ARKit at 60 fps, Rhubarb cues; table validation."""

from __future__ import annotations

import numpy as np
import pytest

import lipclock
from lipclock.errors import TableError, UnknownChoiceError
from lipclock.face.exports import ARKIT, OCULUS, export, load_export_map


@pytest.fixture(scope="module")
def utt():
    return lipclock.synthesize("Mom will buy five oranges, please.")


def data(utt, fmt):
    return export(fmt, utt.timeline, utt.visemes, utt.mouth)


def test_oculus_weights(utt):
    d = data(utt, "oculus")
    w = np.array(d["frames"])
    assert d["visemes"] == list(OCULUS) and w.shape == (utt.mouth.n_frames, 15)
    assert np.allclose(w.sum(axis=1), 1.0, atol=1e-2)
    # during the /m/ of "mom" the PP weight dominates
    m = next(p for p in utt.phones if p.phone == "M")
    k = round((m.start + m.end) / 2 * utt.mouth.rate_hz / utt.sample_rate)
    assert w[k].argmax() == OCULUS.index("PP")


def test_azure_ids_and_offsets(utt):
    ev = data(utt, "azure")
    assert ev[0] == {"VisemeId": 0, "AudioOffset": 0}
    assert all(0 <= e["VisemeId"] <= 21 for e in ev)
    offs = [e["AudioOffset"] for e in ev]
    assert offs == sorted(offs) and offs[-1] < utt.duration_s * 10_000_000
    assert 21 in [e["VisemeId"] for e in ev] and 18 in [e["VisemeId"] for e in ev]  # m, f


def test_arkit_at_60_fps(utt):
    d = data(utt, "arkit")
    f = np.array(d["frames"])
    assert d["fps"] == 60.0 and d["blendshapes"] == list(ARKIT)
    assert abs(len(f) - utt.duration_s * 60) <= 2
    assert f.min() >= 0 and f.max() <= 1 and f[:, 0].max() > 0.3  # the jaw opens


def test_rhubarb_json_and_tsv(utt):
    j = data(utt, "rhubarb-json")
    cues = j["mouthCues"]
    assert cues[0]["start"] == 0 and {c["value"] for c in cues} <= set("ABCDEFGHX")
    assert "A" in {c["value"] for c in cues}  # the bilabials of "mom"
    tsv = data(utt, "rhubarb-tsv").strip().split("\n")
    assert len(tsv) == len(cues) + 1 and tsv[-1].endswith("\tX")


def test_unknown_format_and_bad_tables(utt, tmp_path):
    with pytest.raises(UnknownChoiceError):
        data(utt, "gif")
    bad = tmp_path / "e.tsv"
    bad.write_text("pau\tsil\t0\tX\nP\tPP\t99\tA\n")
    with pytest.raises(TableError, match=":2:.*0-21"):
        load_export_map(bad)
    bad.write_text("QQ\tsil\t0\tX\n")
    with pytest.raises(TableError, match=":1:.*unknown phone"):
        load_export_map(bad)
