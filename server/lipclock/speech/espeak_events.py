"""eSpeak-NG through its C library: audio plus the engine's own phoneme and word events.

This is the timing source for ``system:`` voices on Linux, where pyttsx3's
driver is this same library (libespeak-ng.so.1). We call it with ctypes in
synchronous mode (``AUDIO_OUTPUT_SYNCHRONOUS``), initialised with
``espeakINITIALIZE_PHONEME_EVENTS``, so the synth callback receives the audio
buffers *and* an ``espeak_EVENT`` list in which every phoneme, word and the
end of the message carry ``sample``: the engine's own position of the event on
its output sample clock. Nothing here is estimated or evenly spaced.

Struct and constant values follow ``espeak-ng/speak_lib.h`` (API revision 12).
The library holds global state, so calls are serialised with a lock; the
module reads no clock and opens no socket.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import threading
from dataclasses import dataclass
from functools import cache

import numpy as np

from ..errors import LipclockError

# espeak_AUDIO_OUTPUT
AUDIO_OUTPUT_SYNCHRONOUS = 2
# espeak_Initialize options
INITIALIZE_PHONEME_EVENTS = 0x0001
INITIALIZE_DONT_EXIT = 0x8000
# espeak_EVENT_TYPE
EVENT_LIST_TERMINATED = 0
EVENT_WORD = 1
EVENT_SENTENCE = 2
EVENT_END = 5  # end of a sentence or clause (not used)
EVENT_MSG_TERMINATED = 6
EVENT_PHONEME = 7
# espeak_PARAMETER (absolute values: relative flag 0)
PARAM_RATE = 1
PARAM_VOLUME = 2
RATE_NORMAL_WPM = 175  # espeakRATE_NORMAL
# espeak_Synth flags / position type
CHARS_UTF8 = 1
POS_CHARACTER = 1
EE_OK = 0


class SystemVoiceError(LipclockError):
    """The system speech engine is missing or refused the request."""

    code = "system_voice_unavailable"


class _EventId(ctypes.Union):
    _fields_ = [("number", ctypes.c_int), ("name", ctypes.c_char_p),
                ("string", ctypes.c_char * 8)]


class _Event(ctypes.Structure):
    _fields_ = [
        ("type", ctypes.c_int),
        ("unique_identifier", ctypes.c_uint),
        ("text_position", ctypes.c_int),  # 1-based character position in the text
        ("length", ctypes.c_int),  # characters in the word (WORD events)
        ("audio_position", ctypes.c_int),  # milliseconds (coarse; we use `sample`)
        ("sample", ctypes.c_int),  # sample index on the engine's output clock
        ("user_data", ctypes.c_void_p),
        ("id", _EventId),
    ]


_CALLBACK = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(ctypes.c_short), ctypes.c_int,
                             ctypes.POINTER(_Event))


@dataclass(frozen=True, slots=True)
class EngineEvent:
    kind: str  # "phoneme" | "word" | "end"
    sample: int  # position on the engine's sample clock
    name: str  # eSpeak phoneme mnemonic (phoneme) or the word's text (word)


@dataclass(frozen=True, slots=True)
class EngineOutput:
    samples: np.ndarray  # int16, mono
    sample_rate: int
    events: tuple[EngineEvent, ...]


class _Engine:
    """The loaded library, initialised once in synchronous mode with phoneme events."""

    def __init__(self, lib: ctypes.CDLL) -> None:
        self.lib = lib
        lib.espeak_Initialize.restype = ctypes.c_int
        lib.espeak_Initialize.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_char_p,
                                          ctypes.c_int]
        lib.espeak_SetSynthCallback.argtypes = [_CALLBACK]
        lib.espeak_SetVoiceByName.argtypes = [ctypes.c_char_p]
        lib.espeak_SetVoiceByName.restype = ctypes.c_int
        lib.espeak_SetParameter.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_int]
        lib.espeak_Synth.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_uint,
                                     ctypes.c_int, ctypes.c_uint, ctypes.c_uint,
                                     ctypes.POINTER(ctypes.c_uint), ctypes.c_void_p]
        lib.espeak_Synth.restype = ctypes.c_int
        self.lock = threading.Lock()
        self._chunks: list[np.ndarray] = []
        self._events: list[EngineEvent] = []
        self._text = b""
        self._callback = _CALLBACK(self._on_synth)  # keep a reference: C holds the pointer
        self.sample_rate = self._initialise()

    def _initialise(self) -> int:
        """(Re)initialise in synchronous mode with phoneme events and our callback.

        The library is process-global and pyttsx3's own driver initialises it in
        retrieval mode with its own callback, so we do this before every
        synthesis (it costs about 2 ms).
        """
        rate = self.lib.espeak_Initialize(AUDIO_OUTPUT_SYNCHRONOUS, 200, None,
                                          INITIALIZE_PHONEME_EVENTS | INITIALIZE_DONT_EXIT)
        if rate <= 0:
            raise SystemVoiceError("eSpeak-NG failed to initialise (no espeak-ng-data?)")
        self.lib.espeak_SetSynthCallback(self._callback)
        return int(rate)

    def _on_synth(self, wav: ctypes._Pointer, n_samples: int,  # type: ignore[type-arg]
                  events: ctypes._Pointer) -> int:  # type: ignore[type-arg]
        if n_samples > 0 and wav:
            self._chunks.append(np.ctypeslib.as_array(wav, shape=(n_samples,)).copy())
        i = 0
        while True:
            ev = events[i]
            if ev.type == EVENT_LIST_TERMINATED:
                break
            if ev.type == EVENT_PHONEME:
                raw = bytes(ev.id.string).split(b"\0", 1)[0]
                self._events.append(EngineEvent("phoneme", ev.sample,
                                                raw.decode("utf-8", "replace")))
            elif ev.type == EVENT_WORD:
                start = max(ev.text_position - 1, 0)
                word = self._text[start:start + ev.length].decode("utf-8", "replace")
                self._events.append(EngineEvent("word", ev.sample, word))
            elif ev.type == EVENT_MSG_TERMINATED:
                self._events.append(EngineEvent("end", ev.sample, ""))
            i += 1
        return 0  # 0 = continue synthesis

    def synth(self, text: str, voice: str, rate_wpm: int | None) -> EngineOutput:
        data = text.encode("utf-8")
        with self.lock:
            self.sample_rate = self._initialise()
            if self.lib.espeak_SetVoiceByName(voice.encode("utf-8")) != EE_OK:
                raise SystemVoiceError(f"eSpeak-NG has no voice {voice!r}")
            # Set rate and volume every time: pyttsx3 may have changed them, and the
            # same text must always give the same audio.
            self.lib.espeak_SetParameter(PARAM_RATE, int(rate_wpm or RATE_NORMAL_WPM), 0)
            self.lib.espeak_SetParameter(PARAM_VOLUME, 100, 0)
            self._chunks, self._events, self._text = [], [], data
            buf = ctypes.create_string_buffer(data)
            err = self.lib.espeak_Synth(buf, len(data) + 1, 0, POS_CHARACTER, 0, CHARS_UTF8,
                                        None, None)
            if err != EE_OK:
                raise SystemVoiceError(f"eSpeak-NG synthesis failed (error {err})")
            chunks, events = self._chunks, self._events
            self._chunks, self._events = [], []
        samples = np.concatenate(chunks) if chunks else np.zeros(0, dtype=np.int16)
        return EngineOutput(samples.astype(np.int16, copy=False), self.sample_rate,
                            tuple(events))


@cache
def _engine() -> _Engine:
    name = ctypes.util.find_library("espeak-ng") or "libespeak-ng.so.1"
    try:
        lib = ctypes.CDLL(name)
    except OSError:
        raise SystemVoiceError("libespeak-ng is not installed") from None
    return _Engine(lib)


def available() -> bool:
    """True when libespeak-ng loads and initialises."""
    try:
        _engine()
    except SystemVoiceError:
        return False
    return True


def synthesize_events(text: str, voice: str = "en-us", rate_wpm: int | None = None
                      ) -> EngineOutput:
    """Speak ``text`` with eSpeak-NG voice ``voice``; audio at the engine's native rate."""
    return _engine().synth(text, voice, rate_wpm)
