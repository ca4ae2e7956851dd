"""system: voices (pyttsx3 / eSpeak-NG): event-timed phones, the mnemonic table, fitting."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lipclock.errors import EmptyTextError, TableError, UnknownChoiceError
from lipclock.speech import system_voice as sv
from lipclock.speech.espeak_events import EngineEvent
from lipclock.speech.phoneset import PAUSE, is_valid


def _tiles(phones: list[tuple[str, int, int]], n: int) -> bool:
    return (phones[0][1] == 0 and phones[-1][2] == n
            and all(a[2] == b[1] for a, b in zip(phones, phones[1:], strict=False))
            and all(p[2] > p[1] for p in phones))


# --------------------------------------------------------------------------- table

def test_table_maps_to_known_phones() -> None:
    table = sv.espeak_map()
    assert table["tS"] == ("CH",) and table["A@"] == ("AA1", "R") and table[";"] == ()
    for phones in table.values():
        assert all(p == PAUSE or is_valid(p) for p in phones)


@pytest.mark.parametrize("row, reason", [
    ("k\tKK\n", "unknown ARPAbet"),
    ("a\tAE\n", "unknown ARPAbet"),  # vowel without stress digit
    ("k\n", "expected"),
    ("_\tpau AH0\n", "pau cannot"),
    ("k\tK\nk\tK\n", "duplicate"),
])
def test_bad_table_rows_give_file_line_errors(tmp_path: Path, row: str, reason: str) -> None:
    path = tmp_path / "map.tsv"
    path.write_text("# header\n" + row)
    with pytest.raises(TableError, match=reason) as err:
        sv.load_espeak_map(path)
    assert err.value.line >= 2 and str(path) in str(err.value)


def test_hash_in_mnemonics_is_not_a_comment(tmp_path: Path) -> None:
    path = tmp_path / "map.tsv"
    path.write_text("t#\tT\t# flap\na#\tAH0 # reduced\n")
    assert sv.load_espeak_map(path) == {"t#": ("T",), "a#": ("AH0",)}


def test_unknown_variants_fall_back_to_their_base() -> None:
    assert sv.to_arpabet("t#") == ("T",)
    assert sv.to_arpabet("l/3") == ("L",)  # not in the table: falls back to "l"
    assert sv.to_arpabet("qq") is None


# --------------------------------------------------------------------------- fitting

def test_split_span_tiles_and_follows_inherent_durations() -> None:
    parts = sv.split_span(["AA1", "R"], 1000, 2001)
    assert parts[0][1] == 1000 and parts[-1][2] == 2001 and parts[0][2] == parts[1][1]
    # MITalk inherent durations: AA 240 ms, R 80 ms -> a 3:1 split, not an even one
    assert parts[0][2] - parts[0][1] == pytest.approx(3 * (parts[1][2] - parts[1][1]), abs=2)


def test_fit_phones_in_words_stays_inside_measured_words() -> None:
    words = [("see", 800, 4000), ("this", 5000, 9000)]
    prons = [["S", "IY1"], ["DH", "IH1", "S"]]
    phones = sv.fit_phones_in_words(words, prons, 10000)
    assert _tiles(phones, 10000)
    assert [p[0] for p in phones] == ["pau", "S", "IY1", "pau", "DH", "IH1", "S", "pau"]
    spoken = [p for p in phones if p[0] != PAUSE]
    assert spoken[0][1] == 800 and spoken[1][2] == 4000 and spoken[2][1] == 5000
    lengths = {p[0] + str(i): p[2] - p[1] for i, p in enumerate(spoken)}
    assert len(set(lengths.values())) > 1  # never evenly spaced


def test_phones_from_events_absorbs_markers_and_tiles() -> None:
    events = [EngineEvent("word", 90, "piano"),
              EngineEvent("phoneme", 100, "p"), EngineEvent("phoneme", 300, "i"),
              EngineEvent("phoneme", 450, ";"), EngineEvent("phoneme", 500, "a"),
              EngineEvent("phoneme", 900, "n"), EngineEvent("phoneme", 1100, "oU"),
              EngineEvent("phoneme", 1500, "_:"), EngineEvent("phoneme", 1500, "_")]
    phones = sv.phones_from_events(events, 2000)
    assert _tiles(phones, 2000)
    assert phones == [("pau", 0, 100), ("P", 100, 300), ("IY0", 300, 500), ("AE1", 500, 900),
                      ("N", 900, 1100), ("OW1", 1100, 1500), ("pau", 1500, 2000)]
    assert sv.words_from_events(events, phones) == [("piano", 100, 1500)]


# --------------------------------------------------------------------------- the engine

def _english_voice() -> str:
    pytest.importorskip("pyttsx3")
    from lipclock.speech import espeak_events

    if not espeak_events.available():
        pytest.skip("libespeak-ng not available")
    voices = sv.system_voices()
    for v in ("gmw/en-us", "en-us", "gmw/en"):
        if v in voices:
            return v
    pytest.skip("no English eSpeak voice through pyttsx3 (not the eSpeak driver?)")


def test_system_voice_timings_come_from_engine_events() -> None:
    voice = _english_voice()
    text = "Would you write cheese now? The boat is late."
    out = sv.synthesize_system(text, voice, 16000)
    samples, rate, phones, words = out
    assert rate == 16000 and samples.dtype == np.int16
    assert _tiles(phones, len(samples))
    assert all(p[0] == PAUSE or is_valid(p[0]) for p in phones)
    assert [w[0] for w in words] == ["would", "you", "write", "cheese", "now", "the", "boat",
                                     "is", "late"]
    cheese = [p[0] for p in phones if words[3][1] <= p[1] < words[3][2]]
    assert cheese == ["CH", "IY1", "Z"]
    # The events line up with the sound: vowels are much louder than the pauses.
    x = samples.astype(float)

    def rms(kind: str) -> float:
        spans = [p for p in phones if (p[0] == PAUSE) == (kind == "pause")
                 and (kind == "pause" or p[0][-1] == "1")]
        return float(np.sqrt(np.mean(np.concatenate([x[s:e] for _, s, e in spans]) ** 2)))

    assert rms("vowel") > 5 * rms("pause")


def test_rescale_keeps_tiling_and_maps_the_clock() -> None:
    phones = [("pau", 0, 441), ("S", 441, 2205), ("IY1", 2205, 22050)]
    words = [("see", 441, 22050)]
    new_phones, new_words = sv.rescale_timings(phones, words, 22050, 22050, 16000, 16000)
    assert new_phones == [("pau", 0, 320), ("S", 320, 1600), ("IY1", 1600, 16000)]
    assert new_words == [("see", 320, 16000)]


def test_resampled_output_keeps_phones_and_length() -> None:
    voice = _english_voice()
    text = "Please close the window."
    native = sv.synthesize_system(text, voice, 22050)
    low = sv.synthesize_system(text, voice, 16000)
    assert _tiles(low.phones, len(low.samples))
    assert [p[0] for p in native.phones] == [p[0] for p in low.phones]
    # eSpeak's output drifts a little between calls, so compare durations loosely.
    assert len(low.samples) / 16000 == pytest.approx(len(native.samples) / 22050, rel=0.05)


def test_bad_input_is_typed() -> None:
    voice = _english_voice()
    with pytest.raises(EmptyTextError):
        sv.synthesize_system("   ", voice)
    with pytest.raises(UnknownChoiceError, match="system:"):
        sv.synthesize_system("hello", "no-such-voice")
