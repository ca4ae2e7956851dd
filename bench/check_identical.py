"""Bit-identical output check for speed work: hash everything synthesis produces.

For a fixed corpus (bench/data/prose.txt's lines plus edge cases) x both voices x
a few rates/pitches (and a few sample rates and mouth models), hashes the int16
samples, the Klatt frames, the Timeline (phones, words, F0 targets, phrases), the
visemes, the mouth frames and measures, and the marks JSON. Save a reference before
a change and compare after it; any difference names the case and the part.

    .venv/bin/python bench/check_identical.py --save /tmp/ref.json
    .venv/bin/python bench/check_identical.py --compare /tmp/ref.json
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

import lipclock

HERE = Path(__file__).parent
EXTRA = [
    "Hello.",
    "Is it ready?",
    "Why did the 3 engineers leave at 5:45 p.m. on Jan. 3rd, 2024?!",
    "WOW -- the FBI, NASA and the U.S. Navy... all at once; really: yes (maybe).",
    "Call 555-0199 or e-mail help@example.com, or visit https://lipclock.example.org/docs.",
    "It cost $1,234,567.89, about 12% more than the 1990s estimate of -42.5.",
    "Supercalifragilisticexpialidocious chatbots' zxqv glorptastic unbelievabilities.",
    "Mr. Smith lives on Elm Dr. and Dr. Jones on Mary St.",
    "A\n\nParagraph break; then: the end",
    "Read the record. I will record it, and then I'll read what you've read!",
]
SETTINGS = [(None, None), (120.0, None), (320.0, 190.0), (None, 70.0)]
VOICES = ["adult-low", "adult-high"]


def _h(*parts: Any) -> str:
    h = hashlib.sha256()
    for p in parts:
        if isinstance(p, np.ndarray):
            h.update(str((p.dtype.str, p.shape)).encode())
            h.update(np.ascontiguousarray(p).tobytes())
        else:
            h.update(repr(p).encode())
    return h.hexdigest()[:16]


def digest(text: str, **kw: Any) -> dict[str, str]:
    settings = kw.pop("settings", None) or lipclock.Settings(max_text_chars=len(text) + 1)
    prep = lipclock.prepare(text, settings=settings, **kw)
    utt = prep.render()
    tl = utt.timeline
    m = utt.mouth
    return {
        "samples": _h(utt.samples),
        "frames": _h(prep.work.frames),
        "phones": _h([(p.phone, p.start, p.end, p.word) for p in tl.phones]),
        "words": _h([(w.text, w.start, w.end, w.orth, w.source) for w in tl.words]),
        "f0": _h([(p.sample, p.hz.hex()) for p in tl.f0]),
        "phrases": _h([(p.start, p.end, p.kind.value) for p in tl.phrases]),
        "visemes": _h([(v.viseme, v.start, v.end, v.phone) for v in utt.visemes]),
        "mouth": _h(m.sample_rate, m.rate_hz, m.model, m.nodes, m.frames,
                    sorted((k, v.dtype.str, v.tobytes()) for k, v in m.measures.items())),
        "marks": _h(json.dumps(utt.marks(), sort_keys=True)),
    }


def cases() -> list[tuple[str, str, dict[str, Any]]]:
    prose = (HERE / "data" / "prose.txt").read_text()
    texts = [ln for ln in prose.splitlines() if ln.strip()] + EXTRA
    out = []
    for i, text in enumerate(texts):
        for voice in VOICES:
            for rate, pitch in SETTINGS:
                out.append((f"t{i}/{voice}/r{rate}/p{pitch}", text,
                            {"voice": voice, "rate_wpm": rate, "pitch_hz": pitch}))
    for voice in VOICES:
        out.append((f"prose/{voice}", prose, {"voice": voice}))
    for sr in (8000, 22050, 48000):
        out.append((f"sr{sr}", texts[2], {"settings": lipclock.Settings(sample_rate=sr)}))
    for model in ("linear", "cosine", "bigram"):
        out.append((f"mouth-{model}", texts[3], {"mouth_model": model}))
    out.append(("spring-params", texts[4], {"spring_params": {"lips.stiffness": 15.0}}))
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--save", type=Path)
    g.add_argument("--compare", type=Path)
    args = ap.parse_args()
    result = {name: digest(text, **kw) for name, text, kw in cases()}
    if args.save:
        args.save.write_text(json.dumps(result, indent=1, sort_keys=True))
        print(f"saved {len(result)} cases to {args.save}")
        return 0
    ref = json.loads(args.compare.read_text())
    bad = [(name, part) for name, parts in ref.items() for part, h in parts.items()
           if result.get(name, {}).get(part) != h]
    if set(ref) != set(result):
        print(f"case lists differ: {sorted(set(ref) ^ set(result))}")
        return 1
    for name, part in bad[:40]:
        print(f"DIFFERS: {name}: {part}")
    print(f"{len(result)} cases, {len(bad)} differing parts")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
