"""Voices: data-defined speaker settings (``data/voices.toml``), validated on load."""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import cache
from pathlib import Path

from ..errors import TableError, UnknownChoiceError
from ..tables import finite_float, line_of, load_toml, package_file

# allowed range of every numeric field (inclusive)
RANGES: dict[str, tuple[float, float]] = {
    "base_f0_hz": (50.0, 400.0),
    "f0_range_st": (0.0, 24.0),
    "formant_scale": (0.7, 1.5),
    "breathiness": (0.0, 1.0),
    "open_quotient": (0.3, 0.9),
    "tilt_db": (0.0, 30.0),
    "flutter": (0.0, 100.0),
    "speed": (0.5, 2.0),
}


@dataclass(frozen=True, slots=True)
class Voice:
    name: str
    description: str
    base_f0_hz: float
    f0_range_st: float
    formant_scale: float
    breathiness: float
    open_quotient: float
    tilt_db: float
    flutter: float
    speed: float


def load_voices(path: Path) -> dict[str, Voice]:
    data = load_toml(path)
    voices: dict[str, Voice] = {}
    names = [f.name for f in fields(Voice)]
    for name, table in data.items():
        line = line_of(path, f"[{name}]")
        if not isinstance(table, dict):
            raise TableError(path, line, f"{name}: expected a table")
        unknown = set(table) - set(names)
        if unknown:
            raise TableError(path, line, f"{name}: unknown fields {sorted(unknown)}")
        values: dict[str, object] = {"name": name,
                                     "description": str(table.get("description", ""))}
        for key, (lo, hi) in RANGES.items():
            if key not in table:
                raise TableError(path, line, f"{name}: missing {key}")
            v = finite_float(path, line_of(path, key, line), key, table[key])
            if not lo <= v <= hi:
                raise TableError(path, line_of(path, key, line),
                                 f"{name}.{key}={v} outside {lo}..{hi}")
            values[key] = v
        voices[name] = Voice(**values)  # type: ignore[arg-type]
    if not voices:
        raise TableError(path, 1, "no voices defined")
    return voices


@cache
def _voices() -> dict[str, Voice]:
    return load_voices(package_file("lipclock.speech", "data/voices.toml"))


def voice_names() -> list[str]:
    return sorted(_voices())


def get_voice(name: str) -> Voice:
    try:
        return _voices()[name]
    except KeyError:
        raise UnknownChoiceError("voice", name, voice_names()) from None
