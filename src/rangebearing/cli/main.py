"""``rangebearing`` entry point: parse, dispatch, and turn errors into one clear line."""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from typing import List, Optional

from .. import __version__
from ..errors import ConfigError, RangeBearingError

# Each module exposes register(subparsers) and sets func=run on its parser.
COMMANDS = ("run", "replay", "calibrate", "synth", "record", "listen")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rangebearing",
        description="Range and bearing to red/blue cylinder landmarks, from a camera or recorded frames.",
        epilog="Run 'rangebearing COMMAND --help' for each command's options.",
    )
    parser.add_argument("--version", action="version", version=f"rangebearing {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log debug messages")
    parser.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMANDS:
        try:
            module = importlib.import_module(f".{name}_cmd", __package__)
        except ModuleNotFoundError as exc:  # a command whose module is not in this build
            if exc.name != f"{__package__}.{name}_cmd":
                raise
            continue
        module.register(sub)
    return parser


def main(argv: Optional[List[str]] = None) -> int:
    """Run the command line; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.DEBUG if args.verbose else logging.INFO,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
        stream=sys.stderr,
    )
    try:
        return int(args.func(args) or 0)
    except RangeBearingError as exc:
        if args.debug:
            raise
        print(f"rangebearing: error: {exc}", file=sys.stderr)
        return 2 if isinstance(exc, ConfigError) else 1
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        return 0


if __name__ == "__main__":
    sys.exit(main())
