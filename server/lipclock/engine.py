"""The synthesis pipeline as an ordered list of named stages (DESIGN.md principle 2).

Like flite's ``synth_method_text[]``, every stage takes the work-in-progress
and returns it with one more field filled in. Read the order here:

    normalize -> pronounce -> prosody -> visemes -> mouth -> tracks

and then audio, rendered from the Klatt frames in chunks on demand
(:meth:`Prepared.audio_chunks`), so a server can start playing after the first
chunk. Everything here is pure: no clocks, sockets or asyncio.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .config import Settings
from .errors import OutOfRangeError, UnknownChoiceError
from .face.models import mouth_for
from .face.spring import check_spring_params
from .face.visemes import visemes_for
from .speech import klatt, tracks
from .speech.lexicon import Lexicon, default_lexicon, pronounce
from .speech.normalize import normalize
from .speech.prosody import PITCH_HZ_RANGE, RATE_WPM_RANGE, ProsodySettings, build_timeline
from .speech.timeline import Timeline
from .speech.tokens import Pronounced, Token
from .speech.voices import Voice, get_voice

SUPPORTED_SAMPLE_RATES = (8000, 16000, 22050, 24000, 48000)
FIRST_CHUNK_S = 0.25  # small first chunk: playback starts after ~1 ms of work
FIRST_SECOND_S = 1.0  # the second chunk completes the first second of audio
MAX_CHUNK_S = 0.4  # later chunks end at phrase boundaries or after this much audio


SYSTEM_PREFIX = "system:"


@dataclass(frozen=True)
class Request:
    text: str
    voice: Voice  # Klatt voice (for system voices: the default, used for prosody only)
    prosody: ProsodySettings
    mouth_model: str
    mouth_rate_hz: float
    max_chars: int
    lexicon: Lexicon
    system_voice: str | None = None  # "system:<id>": audio from pyttsx3's engine
    spring_params: tuple[tuple[str, float], ...] = ()  # dynamics.toml overrides


@dataclass(frozen=True)
class Work:
    request: Request
    tokens: tuple[Token, ...] = ()
    pronounced: tuple[Pronounced, ...] = ()
    timeline: Timeline | None = None
    visemes: tuple[Any, ...] = ()
    mouth: Any = None
    frames: np.ndarray | None = None
    samples: np.ndarray | None = None  # set when audio comes from a system voice


def _normalize(w: Work) -> Work:
    r = w.request
    return replace(w, tokens=tuple(normalize(r.text, max_chars=r.max_chars,
                                             is_word=r.lexicon.is_word)))


def _pronounce(w: Work) -> Work:
    return replace(w, pronounced=tuple(pronounce(list(w.tokens), w.request.lexicon)))


def _prosody(w: Work) -> Work:
    return replace(w, timeline=build_timeline(w.pronounced, w.request.prosody))


def _visemes(w: Work) -> Work:
    assert w.timeline is not None
    return replace(w, visemes=tuple(visemes_for(w.timeline)))


def _mouth(w: Work) -> Work:
    assert w.timeline is not None
    r = w.request
    return replace(w, mouth=mouth_for(w.timeline, model=r.mouth_model, rate_hz=r.mouth_rate_hz,
                                      params=dict(r.spring_params) or None))


def _tracks(w: Work) -> Work:
    assert w.timeline is not None
    return replace(w, frames=tracks.klatt_frames(w.timeline, w.request.voice))


Stage = tuple[str, Callable[[Work], Work]]
STAGES: tuple[Stage, ...] = (
    ("normalize", _normalize),
    ("pronounce", _pronounce),
    ("prosody", _prosody),
    ("visemes", _visemes),
    ("mouth", _mouth),
    ("tracks", _tracks),
)


def _system_voice(w: Work) -> Work:
    """Audio and event-timed phones from the platform engine (speech/system_voice.py)."""
    from .speech.phoneset import PAUSE
    from .speech.system_voice import synthesize_system
    from .speech.timeline import F0Point, PhoneSpan, Timeline, WordSpan

    r = w.request
    if len(r.text) > r.max_chars:
        from .errors import TextTooLongError

        raise TextTooLongError(len(r.text), r.max_chars)
    assert r.system_voice is not None
    out = synthesize_system(r.text, r.system_voice, r.prosody.sample_rate,
                            round(r.prosody.rate_wpm))
    words = tuple(WordSpan(t, a, b, t, "system") for t, a, b in out.words)
    starts = [wd.start for wd in words]
    phones = []
    for ph, a, b in out.phones:
        wi = -1
        if ph != PAUSE and starts:
            j = int(np.searchsorted(starts, a, side="right")) - 1
            wi = j if j >= 0 and a < words[j].end else -1
        phones.append(PhoneSpan(ph, a, b, wi))
    timeline = Timeline(out.sample_rate, tuple(phones), words,
                        (F0Point(0, r.prosody.base_f0_hz),))
    return replace(w, timeline=timeline, samples=out.samples)


SYSTEM_STAGES: tuple[Stage, ...] = (
    ("system_voice", _system_voice),
    ("visemes", _visemes),
    ("mouth", _mouth),
)


def run_stages(work: Work, stages: tuple[Stage, ...] = STAGES) -> Work:
    for _name, stage in stages:
        work = stage(work)
    return work


def make_request(text: str, *, voice: str | None = None, rate_wpm: float | None = None,
                 pitch_hz: float | None = None, mouth_model: str | None = None,
                 spring_params: dict[str, float] | None = None,
                 settings: Settings | None = None, lexicon: Lexicon | None = None) -> Request:
    """Resolve the caller's options against Settings and the voice; validate ranges."""
    s = settings or Settings()
    system = None
    if voice and voice.startswith(SYSTEM_PREFIX):
        system, voice = voice, None
    if s.sample_rate not in SUPPORTED_SAMPLE_RATES:
        raise OutOfRangeError("sample_rate", s.sample_rate, min(SUPPORTED_SAMPLE_RATES),
                              max(SUPPORTED_SAMPLE_RATES))
    v = get_voice(voice or s.voice)
    wpm = (rate_wpm if rate_wpm is not None else s.rate_wpm)
    lo, hi = PITCH_HZ_RANGE
    if pitch_hz is not None and not (lo <= pitch_hz <= hi):
        raise OutOfRangeError("pitch_hz", pitch_hz, lo, hi)
    prosody = ProsodySettings(
        sample_rate=s.sample_rate,
        rate_wpm=_voice_rate(_checked_rate(wpm), v),
        base_f0_hz=pitch_hz if pitch_hz is not None else v.base_f0_hz,
        f0_range_st=v.f0_range_st,
        comma_pause_s=s.comma_pause_s,
        period_pause_s=s.period_pause_s,
    )
    model = mouth_model or s.mouth_model
    if spring_params:
        if model != "spring":
            raise UnknownChoiceError("mouth_model for spring_params", model, ("spring",))
        check_spring_params(spring_params)  # unknown keys and ranges fail here, typed
    return Request(text, v, prosody, model, s.mouth_rate_hz,
                   s.max_text_chars, lexicon or _lexicon_for(s), system,
                   tuple(sorted((spring_params or {}).items())))


def _checked_rate(wpm: float) -> float:
    lo, hi = RATE_WPM_RANGE
    if not (lo <= wpm <= hi):
        raise OutOfRangeError("rate_wpm", wpm, lo, hi)
    return float(wpm)


def _voice_rate(wpm: float, voice: Voice) -> float:
    """The voice's ``speed`` scales the requested rate, kept inside the allowed range."""
    lo, hi = RATE_WPM_RANGE
    return min(hi, max(lo, wpm * voice.speed))


_LEXICONS: dict[str, Lexicon] = {}


def _lexicon_for(s: Settings) -> Lexicon:
    if not s.user_lexicon:
        return default_lexicon()
    lex = _LEXICONS.get(s.user_lexicon)
    if lex is None:
        lex = _LEXICONS[s.user_lexicon] = Lexicon.load(s.user_lexicon)
    return lex


def chunk_bounds(timeline: Timeline, first_chunk_s: float = FIRST_CHUNK_S,
                 max_chunk_s: float = MAX_CHUNK_S,
                 first_second_s: float = FIRST_SECOND_S) -> list[int]:
    """End samples of the audio chunks: a small first chunk, then the rest of the first
    second (so a player has all of second 0 at once), then phrase ends, capped in size."""
    sr = timeline.sample_rate
    total = timeline.num_samples
    breaks = sorted({p.end for p in timeline.phrases} | {total})
    first = min(total, max(1, round(first_chunk_s * sr)))
    bounds = [first]
    second = min(total, round(first_second_s * sr))
    if second > first:
        bounds.append(second)
    cap = max(1, round(max_chunk_s * sr))
    for b in breaks:
        while b - bounds[-1] > cap:
            bounds.append(bounds[-1] + cap)
        if b > bounds[-1]:
            bounds.append(b)
    return bounds


def _render(work: Work, bounds: Iterable[int]) -> Iterator[tuple[int, np.ndarray]]:
    """Yield ``(start_sample, int16 samples)`` for consecutive pieces ending at ``bounds``.
    Any choice of bounds gives the same samples (the Klatt renderer is chunk-exact)."""
    assert work.timeline is not None
    if work.samples is not None:  # system voice: the audio exists already
        start = 0
        for end in bounds:
            yield start, work.samples[start:end]
            start = end
        return
    assert work.frames is not None
    r = work.request
    renderer = klatt.KlattRenderer(work.frames, r.prosody.sample_rate, r.voice, seed=0)
    start = 0
    for end in bounds:
        yield start, renderer.render_until(end)
        start = end


def render_chunks(work: Work) -> Iterator[tuple[int, np.ndarray]]:
    """Yield ``(start_sample, int16 samples)`` covering the utterance exactly once, in order."""
    assert work.timeline is not None
    return _render(work, chunk_bounds(work.timeline))


RENDER_PIECE_S = 1.0  # render_all's piece size: fewer kernel calls than streaming chunks


def render_all(work: Work) -> np.ndarray:
    """All the int16 samples at once: exactly :func:`render_chunks`' chunks concatenated,
    made in 1 s pieces into one array."""
    assert work.timeline is not None
    total = work.timeline.num_samples
    step = max(1, round(RENDER_PIECE_S * work.request.prosody.sample_rate))
    out = np.empty(total, dtype=np.int16)
    end = 0
    for start, samples in _render(work, [*range(step, total, step), total]):
        end = start + len(samples)
        out[start:end] = samples
    return out[:end]  # a system voice's audio may end before the timeline does


def prepare_work(text: str, **options: Any) -> Work:
    request = make_request(text, **options)
    stages = SYSTEM_STAGES if request.system_voice else STAGES
    return run_stages(Work(request), stages)
