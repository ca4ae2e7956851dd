"""The Klatt targets table: the packaged one loads, and a bad one names its line."""

from pathlib import Path

import pytest

from lipclock.errors import TableError
from lipclock.speech.targets import load_targets, target_for, targets

PACKAGED = Path(__file__).parents[2] / "server/lipclock/speech/data/klatt_targets.tsv"


def test_packaged_table_covers_every_phone_and_schwa():
    t = targets()
    assert "AX" in t and "NG" in t and "pau" not in t
    assert target_for("AH0") is t["AX"]  # unstressed AH is schwa
    reduced = target_for("AE0").start[1]  # other unstressed vowels move 30% toward it
    assert reduced == pytest.approx(0.7 * t["AE"].start[1] + 0.3 * t["AX"].start[1])


def _table_with(tmp_path: Path, phone: str, row: str | None) -> Path:
    lines = PACKAGED.read_text(encoding="utf-8").splitlines()
    out = [ln for ln in lines if not ln.startswith(phone + "\t")]
    if row is not None:
        out.append(row)
    path = tmp_path / "targets.tsv"
    path.write_text("\n".join(out) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize(("row", "message"), [
    ("IY\t310\t2020", "expected 17 or 20 columns"),
    ("IY\t310\t2020\t2960\t45\t200\t400\t60\t0\t0\t0\t0\t0\t0\t0\t0\tnan", "FNZ"),
    ("IY\t0\t2020\t2960\t45\t200\t400\t60\t0\t0\t0\t0\t0\t0\t0\t0\t270", "positive"),
    ("QQ\t310\t2020\t2960\t45\t200\t400\t60\t0\t0\t0\t0\t0\t0\t0\t0\t270", "unknown phone"),
    (None, "no targets for: IY"),
])
def test_bad_table_names_file_and_line(tmp_path, row, message):
    with pytest.raises(TableError, match=message) as err:
        load_targets(_table_with(tmp_path, "IY", row))
    assert "targets.tsv:" in str(err.value)
