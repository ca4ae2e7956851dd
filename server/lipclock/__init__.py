"""lipclock: text-to-speech with a talking face, stamped on the audio clock.

Public API::

    import lipclock
    utt = lipclock.synthesize("Hello there.", voice="adult-high", rate_wpm=180)
    utt.write_wav("hello.wav"); marks = utt.marks()

    prep = lipclock.prepare("A long answer ...")   # timeline + mouth, no audio yet
    for chunk in prep.audio_chunks():              # stream audio as it is made
        ...
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .config import Settings
from .errors import LipclockError

if TYPE_CHECKING:
    from .speech.voices import Voice
    from .utterance import AudioChunk, Prepared, Utterance

__version__ = "0.1.0"
__all__ = ["AudioChunk", "LipclockError", "Prepared", "Settings", "Utterance", "Voice",
           "prepare", "synthesize"]


def prepare(text: str, *, voice: str | None = None, rate_wpm: float | None = None,
            pitch_hz: float | None = None, mouth_model: str | None = None,
            spring_params: dict[str, float] | None = None,
            settings: Settings | None = None) -> Prepared:
    """Run the front end and mouth models; audio is rendered on demand in chunks.

    ``spring_params`` overrides the spring model's constants for this utterance, keyed
    as in ``viseme_tables/dynamics.toml`` (``"lips.stiffness"``, ``"jaw.damping"``...)."""
    from .engine import prepare_work
    from .utterance import Prepared

    work = prepare_work(text, voice=voice, rate_wpm=rate_wpm, pitch_hz=pitch_hz,
                        mouth_model=mouth_model, spring_params=spring_params,
                        settings=settings)
    return Prepared.from_work(text, work)


def synthesize(text: str, *, voice: str | None = None, rate_wpm: float | None = None,
               pitch_hz: float | None = None, mouth_model: str | None = None,
               spring_params: dict[str, float] | None = None,
               settings: Settings | None = None) -> Utterance:
    """Text -> :class:`Utterance` (samples, phones, words, visemes, mouth, marks())."""
    return prepare(text, voice=voice, rate_wpm=rate_wpm, pitch_hz=pitch_hz,
                   mouth_model=mouth_model, spring_params=spring_params,
                   settings=settings).render()


def __getattr__(name: str) -> object:
    if name in ("Utterance", "Prepared", "AudioChunk"):
        from . import utterance

        return getattr(utterance, name)
    if name == "Voice":
        from .speech.voices import Voice

        return Voice
    raise AttributeError(name)
