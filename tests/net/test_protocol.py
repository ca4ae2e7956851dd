"""Wire messages round-trip (websockets' test_frames.py style) and bad frames are rejected."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from lipclock.net.protocol import (
    CLIENT_MESSAGE,
    SERVER_MESSAGE,
    End,
    Error,
    Hello,
    Mouth,
    Ping,
    Pong,
    Speak,
    Start,
    Stop,
    TextAppend,
    TextFlush,
    pack_audio,
    unpack_audio,
)

CLIENT = [Speak(text="hi", voice="adult-low", rate_wpm=200),
          Speak(text="hi", mouth_model="spring", spring_params={"lips.stiffness": 20.0}),
          TextAppend(text="Hel"),
          TextFlush(), Stop(), Ping(t_client=12.5)]
SERVER = [Hello(sample_rate=16000, channel="c"),
          Start(utterance_id=3, sample_rate=16000, num_samples=100, text="t", voice="v",
                words=[], phones=[{"phone": "pau", "start": 0, "end": 100}], visemes=[],
                mouth_nodes=["a"], mouth_rate_hz=100.0),
          Mouth(utterance_id=3, first_frame=0, first_sample=0, end_sample=160,
                frames=[[[1.0, 2.0]]], lip_gap=[0.5], width=[50.0], jaw=[2.0]),
          End(utterance_id=3, end_sample=100, stopped=True), Pong(t_client=1.0, server_time_s=2.0),
          Error(code="bad_json", reason="x")]


@pytest.mark.parametrize("msg", CLIENT, ids=lambda m: m.type)
def test_client_messages_round_trip(msg):
    assert CLIENT_MESSAGE.validate_json(msg.model_dump_json()) == msg


@pytest.mark.parametrize("msg", SERVER, ids=lambda m: m.type)
def test_server_messages_round_trip(msg):
    assert SERVER_MESSAGE.validate_json(msg.model_dump_json()) == msg


@pytest.mark.parametrize("raw", ['{"type": "speak"}', '{"type": "speak", "text": ""}',
                                 '{"type": "nope"}', '{"type": "ping"}',
                                 '{"type": "stop", "extra": 1}'])
def test_invalid_client_messages_are_rejected(raw):
    with pytest.raises(ValidationError):
        CLIENT_MESSAGE.validate_json(raw)


def test_audio_frame_round_trip_and_errors():
    pcm = bytes(range(10))
    frame = pack_audio(7, 2**40, pcm)
    assert unpack_audio(frame) == (7, 2**40, pcm)
    with pytest.raises(ValueError, match="shorter"):
        unpack_audio(b"LCA")
    with pytest.raises(ValueError, match="magic"):
        unpack_audio(b"XXXX" + frame[4:])
    with pytest.raises(ValueError, match="odd"):
        unpack_audio(frame + b"\x00")
