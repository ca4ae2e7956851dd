"""One WebSocket client's session on a channel (docs/protocol.md), and the device clock's
ticker. net/app.py routes /ws here."""

from __future__ import annotations

import asyncio
import json
import re
import time
from typing import Any

from fastapi import WebSocket
from pydantic import ValidationError
from starlette.websockets import WebSocketDisconnect

from ..config import Settings
from ..errors import LipclockError
from .channels import (
    CHANNEL_RE,
    CLOSE_TOO_SLOW,
    Broker,
    ChannelBusy,
    Job,
    Subscriber,
    UtteranceStore,
    next_utterance_id,
)
from .metrics import Metrics
from .protocol import (
    CLIENT_MESSAGE,
    CLIENT_TYPES,
    Clock,
    Error,
    Hello,
    Ping,
    Pong,
    Speak,
    Stop,
    TextAppend,
    TextFlush,
)

SENTENCE_END = re.compile(r"(?<=[.!?])[\"')\]]*\s+")


async def serve_socket(websocket: WebSocket, s: Settings, broker: Broker, store: UtteranceStore,
                       metrics: Metrics, scope_of: Any, prepare: Any) -> None:
    """One WebSocket client: a sender task drains its queue; this loop reads its messages."""
    origin = websocket.headers.get("origin")
    if s.allowed_origins and origin not in s.allowed_origins:
        await websocket.close(code=4003, reason="origin not allowed")
        return
    scope = scope_of(websocket.query_params.get("key"))
    if scope is None:
        await websocket.close(code=4001, reason="a valid key is required")
        return
    name = websocket.query_params.get("channel", "default")
    if not CHANNEL_RE.match(name):
        await websocket.close(code=4004, reason="bad channel name")
        return
    await websocket.accept()
    metrics.connections += 1
    sub = Subscriber(s.max_client_queue)
    channel = broker.channel(name)
    channel.subscribers.add(sub)
    sender = asyncio.create_task(_send_loop(websocket, sub))
    pending_text = ""

    def reply(msg: Any) -> None:
        sub.offer(msg.model_dump_json())

    def fail(code: str, reason: str) -> None:
        metrics.error(code)
        reply(Error(code=code, reason=reason))

    async def say(text: str, options: dict[str, Any] | None = None) -> None:
        try:
            prep = await prepare(text, options or {})
            uid = next_utterance_id()
            store.put(uid, prep)
            channel.enqueue(Job(uid, prep))
            metrics.utterances += 1
        except LipclockError as exc:
            fail(exc.code, exc.reason)
        except ChannelBusy as exc:
            fail("channel_busy", str(exc))

    reply(Hello(sample_rate=s.sample_rate, channel=name, clock=s.clock))
    if broker.device is not None:
        reply(_clock_message(broker))
    try:
        while not sender.done():
            msg = await websocket.receive()
            if msg["type"] == "websocket.disconnect":
                break
            metrics.messages += 1
            if msg.get("bytes") is not None:
                fail("binary_not_expected", "send JSON text messages; binary is server->client")
                continue
            raw = msg.get("text") or ""
            if len(raw.encode()) > s.max_message_bytes:
                fail("too_large", f"message over {s.max_message_bytes} bytes")
                continue
            try:
                data = json.loads(raw)
            except json.JSONDecodeError as exc:
                fail("bad_json", f"not JSON: {exc.msg} at {exc.pos}")
                continue
            if not isinstance(data, dict) or data.get("type") not in CLIENT_TYPES:
                kind = data.get("type") if isinstance(data, dict) else type(data).__name__
                fail("unknown_type", f"unknown message type {kind!r}; expected one of "
                                     f"{', '.join(CLIENT_TYPES)}")
                continue
            try:
                m = CLIENT_MESSAGE.validate_python(data)
            except ValidationError as exc:
                first = exc.errors()[0]
                fail("bad_message", f"{data['type']}: {'.'.join(map(str, first['loc']))}: "
                                    f"{first['msg']}")
                continue
            if isinstance(m, Ping):
                reply(Pong(t_client=m.t_client, server_time_s=time.monotonic()))
                continue
            if scope != "speak":
                fail("forbidden", "this key may only view")
                continue
            if isinstance(m, Speak):
                await say(m.text, m.options())
            elif isinstance(m, TextAppend):
                pending_text += m.text
                if len(pending_text) > s.max_text_chars:
                    pending_text = ""
                    fail("text_too_long", f"buffered text over {s.max_text_chars} characters; "
                                          "buffer cleared")
                    continue
                parts = SENTENCE_END.split(pending_text)
                pending_text = parts.pop()
                for sentence in parts:
                    if sentence.strip():
                        await say(sentence)
            elif isinstance(m, TextFlush):
                text, pending_text = pending_text, ""
                if text.strip():
                    await say(text)
            elif isinstance(m, Stop):
                channel.stop()
    except WebSocketDisconnect:
        pass
    finally:
        # bookkeeping first: if this task is being cancelled, the await below is cut short
        channel.subscribers.discard(sub)
        metrics.connections -= 1
        sender.cancel()
        broker.drop_if_idle(name)
        await asyncio.gather(sender, return_exceptions=True)


CLOCK_PERIOD_S = 0.1


def _clock_message(broker: Broker) -> Clock:
    assert broker.device is not None
    sample, at = broker.device.position()
    return Clock(device_sample=sample, server_time_s=at)


async def clock_ticker(broker: Broker) -> None:
    """Device mode: tell every subscriber the device clock ten times a second."""
    while True:
        await asyncio.sleep(CLOCK_PERIOD_S)
        if any(ch.subscribers for ch in broker.channels.values()):
            broker.broadcast_all(_clock_message(broker).model_dump_json())


async def _send_loop(websocket: WebSocket, sub: Subscriber) -> None:
    while True:
        item = await sub.queue.get()
        if item is None:  # the client fell too far behind
            await websocket.close(code=CLOSE_TOO_SLOW, reason="client too slow")
            return
        if isinstance(item, bytes):
            await websocket.send_bytes(item)
        else:
            await websocket.send_text(item)
