"""The public API and CLI contracts from DESIGN.md, end to end through the real pipeline."""

from __future__ import annotations

import json
import subprocess
import sys
import wave

import numpy as np
import pytest

import lipclock
from lipclock.cli import main as cli_main
from lipclock.engine import STAGES, chunk_bounds
from lipclock.errors import EmptyTextError, OutOfRangeError, TextTooLongError, UnknownChoiceError

TEXT = "Hello there, my friend. Would you like some tea?"


@pytest.fixture(scope="module")
def utt():
    return lipclock.synthesize(TEXT)


def test_stage_order_is_readable_in_one_place():
    assert [name for name, _ in STAGES] == [
        "normalize", "pronounce", "prosody", "visemes", "mouth", "tracks"]


def test_utterance_contract(utt):
    assert utt.samples.dtype == np.int16 and utt.samples.ndim == 1
    assert len(utt.samples) == utt.timeline.num_samples
    assert utt.sample_rate == 16000
    assert [w.text for w in utt.words][:3] == ["hello", "there", "my"]
    spoken = [p for p in utt.phones if not p.is_pause]
    assert spoken and all(isinstance(p.start, int) and p.end > p.start for p in spoken)
    assert np.abs(utt.samples.astype(np.int32)).max() > 1000  # it actually speaks


def test_marks_contract(utt):
    m = json.loads(json.dumps(utt.marks()))
    assert m["sample_rate"] == utt.sample_rate
    for key in ("words", "phones", "visemes"):
        assert m[key] and all({"start", "end"} <= set(item) for item in m[key])
    mouth = m["mouth"]
    assert {"rate_hz", "nodes", "frames", "measures"} <= set(mouth)
    assert len(mouth["frames"]) == len(mouth["measures"]["lip_gap"])
    # frame k stands at round(k * sample_rate / rate_hz): the last frame is inside the audio
    last = round((len(mouth["frames"]) - 1) * utt.sample_rate / mouth["rate_hz"])
    assert last <= utt.timeline.num_samples


def test_chunks_concatenate_to_the_whole(utt):
    prep = lipclock.prepare(TEXT)
    chunks = list(prep.audio_chunks())
    assert len(chunks) >= 3
    assert chunks[0].start_sample == 0
    for a, b in zip(chunks, chunks[1:], strict=False):
        assert a.end_sample == b.start_sample
    joined = np.concatenate([c.samples for c in chunks])
    assert np.array_equal(joined, utt.samples)


def test_chunk_bounds_small_first_chunk_then_first_second_then_capped():
    prep = lipclock.prepare("This is a fairly long sentence without any commas in it at all "
                            "so the chunker has to split it inside the phrase.")
    bounds = chunk_bounds(prep.timeline, first_chunk_s=0.05, max_chunk_s=0.4,
                          first_second_s=1.0)
    assert bounds[:2] == [800, 16000]  # a small first chunk, then the rest of second 0
    assert bounds[-1] == prep.timeline.num_samples
    assert all(b - a <= 6400 for a, b in zip(bounds[1:], bounds[2:], strict=False))


def test_voices_rate_and_pitch_change_output():
    low = lipclock.synthesize("Good morning.", voice="adult-low")
    high = lipclock.synthesize("Good morning.", voice="adult-high")
    assert high.timeline.f0[0].hz > low.timeline.f0[0].hz
    fast = lipclock.synthesize("Good morning everyone.", rate_wpm=300)
    slow = lipclock.synthesize("Good morning everyone.", rate_wpm=120)
    assert len(fast.samples) < len(slow.samples)
    hi = lipclock.synthesize("Good morning.", pitch_hz=180)
    assert hi.timeline.f0[0].hz > low.timeline.f0[0].hz


@pytest.mark.parametrize("kwargs,exc", [
    ({"voice": "nobody"}, UnknownChoiceError),
    ({"rate_wpm": 10}, OutOfRangeError),
    ({"rate_wpm": 1000}, OutOfRangeError),
    ({"pitch_hz": 5}, OutOfRangeError),
    ({"mouth_model": "puppet"}, UnknownChoiceError),
])
def test_bad_options_are_typed_errors_listing_allowed_values(kwargs, exc):
    with pytest.raises(exc) as info:
        lipclock.synthesize("hello", **kwargs)
    assert "allowed" in info.value.reason


def test_bad_text_is_typed():
    with pytest.raises(EmptyTextError):
        lipclock.synthesize("   \n\t ")
    with pytest.raises(TextTooLongError):
        lipclock.synthesize("a " * 3000)


def test_cli_say_writes_wav_and_marks(tmp_path):
    out, marks = tmp_path / "o.wav", tmp_path / "o.json"
    assert cli_main(["say", "Testing one two three.", "-o", str(out), "--marks", str(marks)]) == 0
    with wave.open(str(out)) as w:
        assert w.getframerate() == 16000 and w.getnframes() > 1000
    m = json.loads(marks.read_text())
    assert m["phones"] and m["mouth"]["frames"]


def test_cli_bad_input_is_one_line_not_a_traceback(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "lipclock.cli", "say", "hi", "--rate", "9",
                           "-o", str(tmp_path / "x.wav")], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "rate_wpm" in proc.stderr


def test_cli_phonemes_format(capsys):
    assert cli_main(["phonemes", "cat", "read"]) == 0
    lines = capsys.readouterr().out.strip().split("\n")
    assert lines[0] == "cat\tK AE1 T"
    assert lines[1].startswith("read\t")


def test_cli_timeline(capsys):
    assert cli_main(["timeline", "Hi there."]) == 0
    out = capsys.readouterr().out
    assert "HH" in out and "pau" in out


def _has_system_voice() -> bool:
    from lipclock.speech.system_voice import system_voices

    return "gmw/en-us" in system_voices()


@pytest.mark.skipif(not _has_system_voice(), reason="no pyttsx3/eSpeak system voice here")
def test_system_voice_through_the_whole_pipeline():
    utt = lipclock.synthesize("Hello there, my friend.", voice="system:gmw/en-us")
    assert utt.voice == "system:gmw/en-us"
    assert len(utt.samples) == utt.timeline.num_samples
    assert [w.text for w in utt.words] == ["hello", "there", "my", "friend"]
    spoken = [p for p in utt.phones if not p.is_pause]
    assert spoken and all(p.word >= 0 for p in spoken)  # every phone sits inside its word
    prep = lipclock.prepare("Hello there, my friend.", voice="system:gmw/en-us")
    joined = np.concatenate([c.samples for c in prep.audio_chunks()])
    assert len(joined) == prep.num_samples and utt.mouth.measures["lip_gap"].max() > 3


@pytest.mark.skipif(not _has_system_voice(), reason="no pyttsx3/eSpeak system voice here")
def test_unknown_system_voice_lists_choices():
    with pytest.raises(UnknownChoiceError) as info:
        lipclock.synthesize("hi", voice="system:klingon")
    assert "system:gmw/en-us" in info.value.reason
