"""Command line: ``lipclock serve | say | phonemes | timeline | plot``.

Thin by design: parse arguments -> Settings -> call the core. Typed input
errors (:class:`lipclock.errors.LipclockError`) are printed as one line and
exit with status 2, never as a traceback.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence

from .config import Settings
from .errors import LipclockError

Handler = Callable[[argparse.Namespace, Settings], int]


def _settings(**fields: object) -> Settings:
    overrides = {k: v for k, v in fields.items() if v is not None}
    return Settings(**overrides)  # type: ignore[arg-type]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="lipclock", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    _add_serve(sub)
    _add_say(sub)
    _add_phonemes(sub)
    _add_timeline(sub)
    _add_plot(sub)
    return parser


# --- serve -----------------------------------------------------------------

def _add_serve(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser("serve", help="start the HTTP/WebSocket server (embedded defaults)")
    p.add_argument("--host", default=None)
    p.add_argument("--port", type=int, default=None)
    p.set_defaults(handler=_serve)


def _serve(args: argparse.Namespace, _: Settings) -> int:
    from .net.app import serve

    serve(_settings(host=args.host, port=args.port))
    return 0


# --- say ---------------------------------------------------------------------

def _add_say(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser("say", help="synthesize TEXT (or -f FILE) to a WAV file")
    p.add_argument("text", nargs="?", help="text to speak (or use -f)")
    p.add_argument("-f", "--file", help="read the text from FILE ('-' for stdin)")
    p.add_argument("-o", "--output", required=True, help="output WAV path")
    p.add_argument("--marks", help="write the marks JSON (words, phones, visemes, mouth) here")
    p.add_argument("--format", dest="export_format", default=None,
                   choices=["oculus", "azure", "arkit", "rhubarb-json", "rhubarb-tsv"],
                   help="add a mouth export to the marks (under 'export')")
    p.add_argument("--voice", default=None)
    p.add_argument("--rate", type=float, default=None, help="words per minute (80-450)")
    p.add_argument("--pitch", type=float, default=None, help="base pitch in Hz (50-400)")
    p.add_argument("--mouth-model", default=None)
    p.add_argument("--sample-rate", type=int, default=None)
    p.set_defaults(handler=_say)


def _read_text(args: argparse.Namespace) -> str:
    if args.file and args.text:
        raise LipclockError("give TEXT or -f FILE, not both")
    if args.file:
        if args.file == "-":
            return sys.stdin.read()
        with open(args.file, encoding="utf-8") as fh:
            return fh.read()
    if args.text is None:
        raise LipclockError("no text: give TEXT or -f FILE")
    return str(args.text)


def _say(args: argparse.Namespace, base: Settings) -> int:
    import json

    from . import synthesize

    settings = _settings(sample_rate=args.sample_rate)
    utt = synthesize(_read_text(args), voice=args.voice, rate_wpm=args.rate,
                     pitch_hz=args.pitch, mouth_model=args.mouth_model, settings=settings)
    utt.write_wav(args.output)
    if args.marks:
        with open(args.marks, "w", encoding="utf-8") as fh:
            json.dump(utt.marks(args.export_format), fh)
    elif args.export_format:
        raise LipclockError("--format needs --marks FILE")
    return 0


# --- phonemes / timeline ------------------------------------------------------

def _add_phonemes(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser("phonemes", help="print word<TAB>ARPAbet phones for each WORD")
    p.add_argument("words", nargs="+")
    p.set_defaults(handler=_phonemes)


def _phonemes(args: argparse.Namespace, settings: Settings) -> int:
    from .engine import _lexicon_for
    from .speech.frontend import text_to_pronounced
    from .speech.tokens import PronouncedWord

    lex = _lexicon_for(settings)
    for word in args.words:
        items = text_to_pronounced(word, max_chars=settings.max_text_chars, lexicon=lex)
        phones = [ph for it in items if isinstance(it, PronouncedWord) for ph in it.phones]
        print(f"{word}\t{' '.join(phones)}")
    return 0


def _add_timeline(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser("timeline", help="print the phones of TEXT with start/end times")
    p.add_argument("text")
    p.add_argument("--rate", type=float, default=None)
    p.add_argument("--voice", default=None)
    p.add_argument("--samples", action="store_true", help="print sample positions, not seconds")
    p.set_defaults(handler=_timeline)


def _timeline(args: argparse.Namespace, settings: Settings) -> int:
    from .engine import Work, _normalize, _pronounce, _prosody, make_request, run_stages

    req = make_request(args.text, voice=args.voice, rate_wpm=args.rate, settings=settings)
    work = run_stages(Work(req), (("normalize", _normalize), ("pronounce", _pronounce),
                                  ("prosody", _prosody)))
    tl = work.timeline
    assert tl is not None
    sr = tl.sample_rate
    print(f"# sample_rate {sr}, {tl.num_samples} samples, {tl.duration_s:.3f} s")
    for p in tl.phones:
        word = tl.words[p.word].text if p.word >= 0 else ""
        if args.samples:
            print(f"{p.start}\t{p.end}\t{p.phone}\t{word}")
        else:
            print(f"{p.start / sr:.3f}\t{p.end / sr:.3f}\t{p.phone}\t{word}")
    return 0


def _add_plot(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser("plot", help="draw waveform, phones and mouth trajectories to a PNG")
    p.add_argument("text")
    p.add_argument("-o", "--output", required=True, help="image path (.png, .svg, .pdf)")
    p.add_argument("--rate", type=float, default=None)
    p.add_argument("--voice", default=None)
    p.set_defaults(handler=_plot)


def _plot(args: argparse.Namespace, settings: Settings) -> int:
    from .plot import plot_utterance

    print(plot_utterance(args.text, args.output, rate_wpm=args.rate, voice=args.voice))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.handler(args, Settings()))
    except LipclockError as exc:
        print(f"lipclock: error: {exc.reason}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"lipclock: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
