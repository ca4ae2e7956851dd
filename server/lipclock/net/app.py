"""The HTTP/WebSocket server: a thin edge that turns wire messages into core calls.

Routes: POST /speak, GET /voices, /mesh, /healthz, /metrics, /utterances/{id}.wav,
/utterances/{id}/marks.json, /, /kiosk and /avatar3d (the browser client), /tables/... (the
viseme tables the client reads), WebSocket /ws (one session per client: net/session.py).
Synthesis runs in worker threads so the event loop stays responsive.
"""

from __future__ import annotations

import asyncio
import contextlib
import gc
import logging
import time
from collections.abc import AsyncIterator
from typing import Any

from fastapi import FastAPI, Header, Request, WebSocket
from fastapi.exceptions import RequestValidationError
from fastapi.responses import FileResponse, JSONResponse, PlainTextResponse, Response
from pydantic import Field

import lipclock

from ..config import Settings
from ..errors import LipclockError, TableError
from ..face.mesh import mesh_json
from ..face.models import MOUTH_MODELS
from ..face.morphs import morph_table, morph_table_path
from ..face.spring import spring_params
from ..speech.system_voice import system_voices
from ..speech.voices import get_voice, voice_names
from ..tables import package_file
from ..utterance import Prepared, wav_bytes
from .channels import (
    CHANNEL_RE,
    Broker,
    ChannelBusy,
    Job,
    UtteranceStore,
    next_utterance_id,
    summary,
)
from .clock import open_device
from .metrics import Metrics
from .protocol import SpeechOptions
from .session import clock_ticker, serve_socket

log = logging.getLogger("lipclock.server")
CLIENT_DIR = package_file("lipclock.client", "")  # client/ ships inside the wheel


class SpeakRequest(SpeechOptions):
    text: str = Field(min_length=1)
    channel: str = "default"


def _error(status: int, code: str, reason: str) -> JSONResponse:
    return JSONResponse({"error": {"code": code, "reason": reason}}, status_code=status)


def create_app(settings: Settings | None = None) -> FastAPI:
    s = settings or Settings()
    device = open_device(s.sample_rate, s.audio_device) if s.clock == "device" else None

    @contextlib.asynccontextmanager
    async def lifespan(_: FastAPI) -> AsyncIterator[None]:
        ticker = asyncio.create_task(clock_ticker(broker)) if device is not None else None
        try:
            yield
        finally:
            if ticker is not None:
                ticker.cancel()
                await asyncio.gather(ticker, return_exceptions=True)
            if device is not None:
                device.close()

    app = FastAPI(title="lipclock", version=lipclock.__version__, lifespan=lifespan,
                  description="Text-to-speech with a talking face, stamped on the audio clock.")
    broker = Broker(s.max_queued_utterances, device)
    store = UtteranceStore(s.utterance_store)
    metrics = Metrics()
    app.state.broker, app.state.store, app.state.metrics = broker, store, metrics

    def scope_of(key: str | None) -> str | None:
        """'speak', 'view' or None (no valid key). Open server: everyone may speak."""
        if not s.auth_enabled:
            return "speak"
        if key and key in s.speak_keys:
            return "speak"
        if key and key in s.view_keys:
            return "view"
        return None

    async def prepare(text: str, options: dict[str, Any]) -> Prepared:
        t0 = time.perf_counter()
        prep = await asyncio.to_thread(lambda: lipclock.prepare(text, settings=s, **options))
        metrics.observe_prepare(time.perf_counter() - t0, prep.duration_s)
        return prep

    @app.exception_handler(RequestValidationError)
    async def _invalid(_: Request, exc: RequestValidationError) -> JSONResponse:
        # FastAPI's default handler echoes the input, and crashes on NaN/Infinity in it
        errors = [{"loc": [str(x) for x in e.get("loc", ())], "msg": str(e.get("msg", "")),
                   "type": str(e.get("type", ""))} for e in exc.errors()]
        reason = "; ".join(f"{'.'.join(e['loc'])}: {e['msg']}" for e in errors[:3])
        metrics.error("bad_request")
        return JSONResponse({"error": {"code": "bad_request", "reason": reason},
                             "detail": errors}, status_code=422)

    @app.exception_handler(LipclockError)
    async def _lipclock_error(_: Request, exc: LipclockError) -> JSONResponse:
        metrics.error(exc.code)
        return _error(400, exc.code, exc.reason)

    @app.post("/speak", summary="Speak text on a channel",
              responses={200: {"content": {"audio/wav": {}}}})
    async def speak(req: SpeakRequest, request: Request, accept: str | None = Header(None),
                    x_api_key: str | None = Header(None),
                    authorization: str | None = Header(None)) -> Response:
        key = x_api_key or (authorization[7:] if authorization and
                            authorization.lower().startswith("bearer ") else None)
        scope = scope_of(key)
        if scope is None:
            return _error(401, "unauthorized", "a valid API key is required (X-API-Key)")
        if scope != "speak":
            return _error(403, "forbidden", "this key may only view")
        if not CHANNEL_RE.match(req.channel):
            return _error(400, "bad_channel", "channel names are 1-64 of A-Z a-z 0-9 _ . -")
        prep = await prepare(req.text, req.options())
        uid = next_utterance_id()
        store.put(uid, prep)
        try:
            broker.channel(req.channel).enqueue(Job(uid, prep))
        except ChannelBusy as exc:
            return _error(429, "channel_busy", str(exc))
        metrics.utterances += 1
        base = str(request.base_url).rstrip("/")
        marks_url = f"{base}/utterances/{uid}/marks.json"
        if accept and "audio/wav" in accept:
            audio = await asyncio.to_thread(lambda: prep.render().wav_bytes())
            return Response(audio, media_type="audio/wav", headers={"X-Marks-URL": marks_url})
        body = summary(uid, prep)
        body.update(audio_url=f"{base}/utterances/{uid}.wav", marks_url=marks_url,
                    channel=req.channel)
        return JSONResponse(body)

    @app.get("/voices")
    async def voices() -> dict[str, Any]:
        return {"voices": [{"name": n, "description": get_voice(n).description,
                            "base_f0_hz": get_voice(n).base_f0_hz} for n in voice_names()],
                "system_voices": ["system:" + v for v in system_voices()],
                "default": s.voice, "mouth_models": list(MOUTH_MODELS),
                "spring_params": spring_params(),
                "sample_rate": s.sample_rate}

    @app.get("/mesh", summary="The mouth-node mesh: names, rest positions, edges, triangles")
    async def mesh() -> dict[str, Any]:
        return mesh_json()

    @app.get("/healthz")
    async def healthz() -> dict[str, Any]:
        return {"status": "ok", "version": lipclock.__version__,
                "channels": len(broker.channels)}

    @app.get("/metrics", response_class=PlainTextResponse)
    async def prometheus() -> str:
        return metrics.render(broker)

    @app.get("/utterances/{uid}.wav")
    async def utterance_wav(uid: int) -> Response:
        prep = store.get(uid)
        if prep is None:
            return _error(404, "unknown_utterance", f"utterance {uid} is not (or no longer) kept")
        audio = await asyncio.to_thread(lambda: wav_bytes(prep.render().samples,
                                                          prep.sample_rate))
        return Response(audio, media_type="audio/wav")

    @app.get("/utterances/{uid}/marks.json")
    async def utterance_marks(uid: int) -> Response:
        prep = store.get(uid)
        if prep is None:
            return _error(404, "unknown_utterance", f"utterance {uid} is not (or no longer) kept")
        return JSONResponse(prep.marks())

    def client_file(name: str) -> Response:
        try:  # a NUL or an over-long name is just a file that isn't there
            path = (CLIENT_DIR / name).resolve()
            found = CLIENT_DIR.resolve() in path.parents and path.is_file()
        except (ValueError, OSError):
            found = False
        if not found:
            return _error(404, "not_found", f"client file {name!r} not found")
        return FileResponse(path)

    @app.get("/", include_in_schema=False)
    async def index() -> Response:
        return client_file("index.html")

    @app.get("/kiosk", include_in_schema=False)
    async def kiosk() -> Response:
        return client_file("kiosk.html")

    @app.get("/avatar3d", include_in_schema=False)
    async def avatar3d() -> Response:
        return client_file("avatar3d.html")

    # the viseme tables the browser client reads, checked first: a bad table is the
    # server's fault (500), reported with its file:line
    client_tables = {"morphs.tsv": (morph_table, morph_table_path)}

    @app.get("/tables/{name}", include_in_schema=False)
    async def client_table(name: str) -> Response:
        if name not in client_tables:
            return _error(404, "not_found", f"table {name!r} is not served")
        check, path = client_tables[name]
        try:
            check()
        except TableError as exc:
            log.error("%s", exc.reason)
            return _error(500, exc.code, exc.reason)
        return FileResponse(path(), media_type="text/tab-separated-values; charset=utf-8")

    @app.get("/client/{name:path}", include_in_schema=False)
    async def client_static(name: str) -> Response:
        return client_file(name)

    @app.websocket("/ws")
    async def ws(websocket: WebSocket) -> None:
        await serve_socket(websocket, s, broker, store, metrics, scope_of, prepare)

    return app


def serve(settings: Settings) -> None:
    """Run the server with uvicorn (embedded defaults: in-process channels, no services)."""
    import uvicorn

    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    if not settings.auth_enabled:
        if settings.host not in ("127.0.0.1", "localhost", "::1"):
            log.warning("no API keys configured: refusing to listen on %s; binding 127.0.0.1",
                        settings.host)
            settings = settings.model_copy(update={"host": "127.0.0.1"})
        log.warning("no API keys configured: the server is open to anyone on this machine")
    lipclock.synthesize("Ready.", settings=settings)  # load the lexicon and tables: ready to speak
    # The lexicon and tables are millions of long-lived objects; a full collection walking
    # them stalled a request now and then by tens of milliseconds. Freeze them out of the
    # collector's view (bench_server_latency.py p99).
    gc.collect()
    gc.freeze()
    # permessage-deflate off: every broadcast would be compressed once per connection,
    # which dominated server CPU with many subscribers (bench_server_fanout.py)
    uvicorn.run(create_app(settings), host=settings.host, port=settings.port,
                log_level="info", ws_max_size=settings.max_message_bytes * 2,
                ws_per_message_deflate=False)
