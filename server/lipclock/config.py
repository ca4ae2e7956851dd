"""One typed Settings object, fed by CLI flags and ``LIPCLOCK_*`` environment variables.

Precedence: explicit CLI flags > environment > defaults embedded here.
"""

from __future__ import annotations

from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict


class Settings(BaseSettings):
    model_config = SettingsConfigDict(env_prefix="LIPCLOCK_", extra="ignore")

    # --- speech ---
    sample_rate: int = Field(16000, description="Output sample rate in Hz")
    voice: str = Field("adult-low", description="Default voice name")
    rate_wpm: float = Field(170.0, ge=80, le=450, description="Default speaking rate")
    comma_pause_s: float = Field(0.25, ge=0.0, le=3.0)
    period_pause_s: float = Field(0.55, ge=0.0, le=5.0)
    max_text_chars: int = Field(5000, ge=1, description="Longest text accepted, in characters")
    user_lexicon: str | None = Field(None, description="Path to a user lexicon file")
    mouth_model: str = Field("spring", description="Default mouth motion model")
    mouth_rate_hz: float = Field(100.0, gt=0, le=1000)

    # --- server ---
    host: str = "127.0.0.1"
    port: int = 8000
