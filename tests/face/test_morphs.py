"""viseme_tables/morphs.tsv: loads, agrees with exports.tsv, fails with file:line, is served."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

import lipclock.net.app as app_module
from lipclock.config import Settings
from lipclock.errors import TableError
from lipclock.face.exports import export_map
from lipclock.face.morphs import (
    OCULUS_MORPHS,
    load_morph_table,
    morph_of,
    morph_table,
    morph_table_path,
)
from lipclock.face.visemes import shapes
from lipclock.speech.phoneset import phones


def load(path):
    return load_morph_table(path, set(shapes()), set(phones()))


def test_shipped_table_covers_every_class_and_matches_the_oculus_export():
    table = morph_table()
    assert set(shapes()) <= set(table)
    assert morph_of("P") == "viseme_PP" and morph_of("AA1") == "viseme_aa"
    spelt = dict(zip(("sil", "PP", "FF", "TH", "DD", "kk", "CH", "SS", "nn", "RR", "aa", "E",
                      "ih", "oh", "ou"), OCULUS_MORPHS, strict=True))
    # the 3-D adaptor and the server's Oculus export must show every phone the same way
    wrong = {ph: (morph_of(ph), spelt[oc]) for ph, (oc, _, _) in export_map().items()
             if morph_of(ph) != spelt[oc]}
    assert not wrong, wrong


@pytest.mark.parametrize(("line", "message"), [
    ("closed\tviseme_XX", "unknown morph 'viseme_XX'"),
    ("lips\tviseme_PP", "'lips' is neither a viseme class nor a phone"),
    ("closed", "expected 2 columns"),
    ("closed\tviseme_PP\textra", "expected 2 columns"),
    ("rest\tviseme_sil", "'rest' is given twice"),
])
def test_a_bad_line_is_reported_with_file_and_line(tmp_path, line, message):
    src = morph_table_path().read_text().splitlines()
    number = next(i for i, s in enumerate(src, start=1) if s.startswith("closed\t")) + 1
    src.insert(number - 1, line)
    bad = tmp_path / "morphs.tsv"
    bad.write_text("\n".join(src) + "\n")
    with pytest.raises(TableError, match=message) as err:
        load(bad)
    assert str(err.value).startswith(f"{bad}:{number}:")


def test_a_class_without_a_row_is_an_error(tmp_path):
    bad = tmp_path / "morphs.tsv"
    bad.write_text("".join(s + "\n" for s in morph_table_path().read_text().splitlines()
                           if not s.startswith("velar\t")))
    with pytest.raises(TableError, match="viseme classes without a morph: velar"):
        load(bad)


def test_server_serves_the_table_and_refuses_a_bad_one(monkeypatch, tmp_path):
    with TestClient(app_module.create_app(Settings())) as c:
        r = c.get("/tables/morphs.tsv")
        assert r.status_code == 200 and "closed\tviseme_PP" in r.text
        assert r.headers["content-type"].startswith("text/tab-separated-values")
        assert c.get("/tables/visemes.tsv").status_code == 404
        assert c.get("/tables/..%2Fpyproject.toml").status_code == 404
    bad = tmp_path / "morphs.tsv"
    bad.write_text("closed\tviseme_XX\n")
    monkeypatch.setattr(app_module, "morph_table", lambda: load(bad))
    with TestClient(app_module.create_app(Settings())) as c:
        r = c.get("/tables/morphs.tsv")
    assert r.status_code == 500
    assert r.json()["error"]["reason"].startswith(f"{bad}:1: unknown morph")
