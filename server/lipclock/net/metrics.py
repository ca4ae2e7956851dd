"""Prometheus text-format metrics (no client library needed for a handful of series)."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any


@dataclass
class Metrics:
    utterances: int = 0
    connections: int = 0
    messages: int = 0
    prepare_seconds: float = 0.0
    audio_seconds: float = 0.0
    errors: Counter[str] = field(default_factory=Counter)

    def error(self, code: str) -> None:
        self.errors[code] += 1

    def observe_prepare(self, seconds: float, audio_s: float) -> None:
        self.prepare_seconds += seconds
        self.audio_seconds += audio_s

    def render(self, broker: Any) -> str:
        lines = [
            "# HELP lipclock_utterances_total Utterances accepted for speaking.",
            "# TYPE lipclock_utterances_total counter",
            f"lipclock_utterances_total {self.utterances}",
            "# HELP lipclock_ws_connections WebSocket clients connected now.",
            "# TYPE lipclock_ws_connections gauge",
            f"lipclock_ws_connections {self.connections}",
            "# HELP lipclock_ws_messages_total Client messages received.",
            "# TYPE lipclock_ws_messages_total counter",
            f"lipclock_ws_messages_total {self.messages}",
            "# HELP lipclock_channels Channels that exist now.",
            "# TYPE lipclock_channels gauge",
            f"lipclock_channels {len(broker.channels)}",
            "# HELP lipclock_prepare_seconds_total Wall time spent preparing utterances.",
            "# TYPE lipclock_prepare_seconds_total counter",
            f"lipclock_prepare_seconds_total {self.prepare_seconds:.6f}",
            "# HELP lipclock_audio_seconds_total Audio prepared, in seconds.",
            "# TYPE lipclock_audio_seconds_total counter",
            f"lipclock_audio_seconds_total {self.audio_seconds:.3f}",
            "# HELP lipclock_errors_total Typed input errors by code.",
            "# TYPE lipclock_errors_total counter",
        ]
        lines += [f'lipclock_errors_total{{code="{c}"}} {n}'
                  for c, n in sorted(self.errors.items())]
        return "\n".join(lines) + "\n"
