"""Wire protocol v1: typed JSON messages and the binary audio frame (docs/protocol.md).

Pure: no I/O. JSON messages are pydantic models discriminated by ``type``;
audio travels as binary frames with a 16-byte header::

    magic b"LCA1" | uint32 utterance_id | uint64 first_sample | PCM16 LE mono ...
"""

from __future__ import annotations

import struct
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, TypeAdapter

PROTOCOL_VERSION = 1
AUDIO_MAGIC = b"LCA1"
AUDIO_HEADER = struct.Struct("<4sIQ")


class _Msg(BaseModel):
    model_config = ConfigDict(extra="forbid")


# --- client -> server --------------------------------------------------------

class SpeechOptions(BaseModel):
    """How to say it: shared by the WebSocket ``speak`` message and ``POST /speak``."""

    voice: str | None = None
    rate_wpm: float | None = None
    pitch_hz: float | None = None
    mouth_model: str | None = None
    # spring model constants for this utterance, keyed as in viseme_tables/dynamics.toml
    # ("lips.stiffness": N/m, "lips.damping": N*s/m, ...); GET /voices lists the defaults
    spring_params: dict[str, float] | None = Field(None, max_length=32)

    def options(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in SpeechOptions.model_fields}


class Speak(_Msg, SpeechOptions):
    type: Literal["speak"] = "speak"
    text: str = Field(min_length=1)


class TextAppend(_Msg):
    type: Literal["text.append"] = "text.append"
    text: str


class TextFlush(_Msg):
    type: Literal["text.flush"] = "text.flush"


class Stop(_Msg):
    type: Literal["stop"] = "stop"


class Ping(_Msg):
    type: Literal["ping"] = "ping"
    t_client: float  # client's clock, any unit it likes; echoed back


ClientMessage = Annotated[Speak | TextAppend | TextFlush | Stop | Ping,
                          Field(discriminator="type")]
CLIENT_MESSAGE: TypeAdapter[Any] = TypeAdapter(ClientMessage)
CLIENT_TYPES = ("speak", "text.append", "text.flush", "stop", "ping")


# --- server -> client --------------------------------------------------------

class Hello(_Msg):
    type: Literal["hello"] = "hello"
    protocol_version: int = PROTOCOL_VERSION
    sample_rate: int
    channel: str
    clock: Literal["client", "device"] = "client"


class Start(_Msg):
    type: Literal["start"] = "start"
    utterance_id: int
    sample_rate: int
    num_samples: int
    text: str
    voice: str
    words: list[dict[str, Any]]
    phones: list[dict[str, Any]]
    visemes: list[dict[str, Any]]
    mouth_nodes: list[str]
    mouth_rate_hz: float
    device_start: int | None = None  # device mode: device sample where sample 0 plays


class Mouth(_Msg):
    """Mouth frames ``first_frame..``; frame k stands at sample round(k*sample_rate/rate_hz)."""

    type: Literal["mouth"] = "mouth"
    utterance_id: int
    first_frame: int
    first_sample: int
    end_sample: int  # mouth data covers samples [first_sample, end_sample)
    frames: list[list[list[float]]]
    lip_gap: list[float]
    width: list[float]
    jaw: list[float]


class End(_Msg):
    type: Literal["end"] = "end"
    utterance_id: int
    end_sample: int  # the last sample played (exclusive); < num_samples when stopped
    stopped: bool = False


class Clock(_Msg):
    """Device mode: the device was playing ``device_sample`` at server time ``server_time_s``."""

    type: Literal["clock"] = "clock"
    device_sample: int
    server_time_s: float


class Pong(_Msg):
    type: Literal["pong"] = "pong"
    t_client: float
    server_time_s: float


class Error(_Msg):
    type: Literal["error"] = "error"
    code: str
    reason: str


ServerMessage = Annotated[Hello | Start | Mouth | End | Clock | Pong | Error,
                          Field(discriminator="type")]
SERVER_MESSAGE: TypeAdapter[Any] = TypeAdapter(ServerMessage)


def pack_audio(utterance_id: int, first_sample: int, pcm16: bytes) -> bytes:
    return AUDIO_HEADER.pack(AUDIO_MAGIC, utterance_id, first_sample) + pcm16


def unpack_audio(frame: bytes) -> tuple[int, int, bytes]:
    """-> (utterance_id, first_sample, pcm16 bytes). Raises ValueError on a bad frame."""
    if len(frame) < AUDIO_HEADER.size:
        raise ValueError("audio frame shorter than its header")
    magic, uid, first = AUDIO_HEADER.unpack_from(frame)
    if magic != AUDIO_MAGIC:
        raise ValueError(f"bad audio magic {magic!r}")
    if (len(frame) - AUDIO_HEADER.size) % 2:
        raise ValueError("PCM16 payload has an odd length")
    return uid, first, frame[AUDIO_HEADER.size:]
