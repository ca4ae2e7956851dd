"""One typed Settings object, fed by CLI flags and ``LIPCLOCK_*`` environment variables.

Precedence: explicit CLI flags > environment > defaults embedded here.
"""

from __future__ import annotations

from typing import Literal

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
    speak_keys: list[str] = Field(default_factory=list,
                                  description="API keys that may make a channel talk")
    view_keys: list[str] = Field(default_factory=list, description="API keys that may only watch")
    allowed_origins: list[str] = Field(default_factory=list,
                                       description="WebSocket Origin allow-list (empty: any)")
    max_message_bytes: int = Field(65536, ge=256, description="Largest WebSocket message")
    max_client_queue: int = Field(1024, ge=8, description="Messages buffered per client")
    max_queued_utterances: int = Field(8, ge=1, description="Utterances waiting per channel")
    utterance_store: int = Field(64, ge=1, description="Recent utterances kept for download")
    clock: Literal["client", "device"] = Field(
        "client", description="client: each browser plays the audio; device: this server "
        "plays it and broadcasts the device clock (kiosk)")
    audio_device: str = Field("auto", description="device mode output: auto (PortAudio if "
                              "present, else simulated), simulated, or a PortAudio device")

    @property
    def auth_enabled(self) -> bool:
        return bool(self.speak_keys or self.view_keys)
