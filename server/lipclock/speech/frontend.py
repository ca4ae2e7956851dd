"""The text front end: text -> tokens -> pronounced words -> Timeline.

Three pure stages, in this order: :func:`normalize` (speech/normalize.py),
:func:`pronounce` (speech/lexicon.py: user lexicon -> CMUdict -> LTS) and
:func:`build_timeline` (speech/prosody.py).
"""

from __future__ import annotations

from .lexicon import Lexicon, default_lexicon, pronounce
from .normalize import normalize
from .prosody import ProsodySettings, build_timeline
from .timeline import Timeline
from .tokens import Pronounced


def text_to_pronounced(text: str, *, max_chars: int = 5000,
                       lexicon: Lexicon | None = None) -> list[Pronounced]:
    lex = lexicon or default_lexicon()
    tokens = normalize(text, max_chars=max_chars, is_word=lex.is_word)
    return pronounce(tokens, lex)


def text_to_timeline(text: str, *, sample_rate: int = 16000, rate_wpm: float = 170.0,
                     base_f0_hz: float = 110.0, f0_range_st: float = 6.0,
                     comma_pause_s: float = 0.25, period_pause_s: float = 0.55,
                     max_chars: int = 5000, lexicon: Lexicon | None = None) -> Timeline:
    """Convenience wrapper for tools and tests: the front end with explicit prosody settings."""
    settings = ProsodySettings(sample_rate, rate_wpm, base_f0_hz, f0_range_st,
                               comma_pause_s, period_pause_s)
    return build_timeline(text_to_pronounced(text, max_chars=max_chars, lexicon=lexicon),
                          settings)
