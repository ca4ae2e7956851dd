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


def _settings(args: argparse.Namespace, **fields: object) -> Settings:
    overrides = {k: v for k, v in fields.items() if v is not None}
    return Settings(**overrides)  # type: ignore[arg-type]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="lipclock", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    _add_serve(sub)
    return parser


# --- serve -----------------------------------------------------------------

def _add_serve(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser("serve", help="start the HTTP/WebSocket server (embedded defaults)")
    p.add_argument("--host", default=None)
    p.add_argument("--port", type=int, default=None)
    p.set_defaults(handler=_serve)


def _serve(args: argparse.Namespace, _: Settings) -> int:
    from .net.app import serve

    serve(_settings(args, host=args.host, port=args.port))
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
