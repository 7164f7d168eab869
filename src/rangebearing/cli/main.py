"""``rangebearing`` entry point: parse, dispatch, and turn every error into one clear line.

The one error funnel (gpiozero's ``CliTool.__call__`` is the model): commands
raise, and only :func:`main` prints ``rangebearing: error: …`` and picks the
exit status. The traceback is shown only with ``--debug`` or
``RANGEBEARING_DEBUG=1``. Each command's module is imported only when that
command runs, so ``rangebearing run`` on a Pi never loads the renderer, the
evaluation code or the calibration fit.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib
import logging
import os
import sys
import threading
from typing import IO, Dict, List, Optional

from .. import __version__, _signals
from ..errors import ConfigError, RangeBearingError

# name -> one-line help; the module cli/<name>_cmd.py has register(subparsers) and sets func=run.
COMMANDS: Dict[str, str] = {
    "run": "run the daemon: camera → pipeline → UDP (and Zenoh) readings",
    "listen": "print readings published by rangebearing daemons",
    "replay": "run the pipeline over recorded frames",
    "calibrate": "fit the range model to frames with known range and bearing",
    "record": "save frames from a source as numbered images or one MCAP file",
    "swarm": "live view of every robot's presence and readings",
    "synth": "render synthetic frames with exact ground truth",
    "intrinsics": "camera intrinsics and lens distortion from chessboard frames",
    "tune": "lock exposure and white balance and fit the colour thresholds to a landmark in view",
    "view": "serve a live web page of what the camera sees, with threshold controls",
}

EXIT_ERROR = 1
EXIT_CONFIG = 2  # a bad config or command line, as argparse does
EXIT_INTERRUPTED = 130


class _Formatter(argparse.HelpFormatter):
    """argparse's help layout, its width found as ``shutil`` does, without importing it (with bz2, lzma: ~3 ms).

    argparse builds a formatter at every ``add_argument``, so the default one
    imports ``shutil`` in every start of every command.
    """

    def __init__(self, prog: str, indent_increment: int = 2, max_help_position: int = 24,
                 width: Optional[int] = None) -> None:
        super().__init__(prog, indent_increment, max_help_position, _columns() - 2 if width is None else width)


def _columns() -> int:
    """``shutil.get_terminal_size().columns``: ``$COLUMNS``, else stdout's terminal, else 80."""
    try:
        columns = int(os.environ.get("COLUMNS", "0"))
    except ValueError:
        columns = 0
    if columns <= 0:
        try:
            columns = os.get_terminal_size(sys.__stdout__.fileno()).columns  # type: ignore[union-attr]
        except (AttributeError, ValueError, OSError):
            columns = 0
    return columns if columns > 0 else 80


class _Parser(argparse.ArgumentParser):
    """argparse's parser, but ``--help`` / ``--version`` that cannot be written (``> /dev/full``) are an error.

    argparse drops an OSError from writing them and exits 0; stdout is flushed
    here so the failure reaches :func:`main`'s funnel, as any other write's does.
    """

    def _print_message(self, message: str, file: Optional[IO[str]] = None) -> None:
        if not message or (file is not None and file is not sys.stdout):
            super()._print_message(message, file)  # usage and errors on stderr: nothing to tell if it fails
            return
        sys.stdout.write(message)
        sys.stdout.flush()


def common_options() -> argparse.ArgumentParser:
    """Options accepted both before and after the command name (``rangebearing -v run`` = ``run -v``)."""
    p = _Parser(add_help=False, formatter_class=_Formatter)
    p.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS, help="log debug messages")
    p.add_argument(
        "--debug", action="store_true", default=argparse.SUPPRESS, help="show the traceback of an error"
    )
    return p


def chosen_command(argv: List[str]) -> Optional[str]:
    """The command named in ``argv``: the first argument that is not an option."""
    for arg in argv:
        if arg == "--":
            return None
        if not arg.startswith("-"):
            return arg if arg in COMMANDS else None
    return None


def build_parser(argv: Optional[List[str]] = None) -> argparse.ArgumentParser:
    """The parser; only the command named in ``argv`` (all of them when ``None``) is imported."""
    common = common_options()
    parser = _Parser(
        prog="rangebearing",
        description="Range and bearing to red/blue cylinder landmarks, from a camera or recorded frames.",
        epilog="Run 'rangebearing COMMAND --help' for each command's options.",
        parents=[common],
        formatter_class=_Formatter,
    )
    parser.add_argument("--version", action="version", version=f"rangebearing {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    wanted = chosen_command(argv) if argv is not None else None
    for name, help_text in COMMANDS.items():
        if argv is None or name == wanted:
            module = importlib.import_module(f".{name}_cmd", __package__)
            module.register(_WithCommon(sub, common))
        else:  # listed in --help, not imported
            sub.add_parser(name, help=help_text, add_help=False, formatter_class=_Formatter)
    return parser


class _WithCommon:
    """Wraps ``add_subparsers()`` so every command also takes the common options."""

    def __init__(self, sub: argparse._SubParsersAction, common: argparse.ArgumentParser) -> None:
        self._sub, self._common = sub, common

    def add_parser(self, name: str, **kwargs: object) -> argparse.ArgumentParser:
        parents = [*kwargs.pop("parents", []), self._common]  # type: ignore[misc]
        kwargs.setdefault("formatter_class", _Formatter)
        return self._sub.add_parser(name, parents=parents, **kwargs)  # type: ignore[arg-type]


def describe_error(exc: BaseException) -> str:
    """One line (or one block, for a config's problem list) that tells a user what went wrong."""
    if isinstance(exc, RangeBearingError):
        return str(exc)
    if isinstance(exc, OSError):
        where = " ".join(f"{f}:" for f in (exc.filename, exc.filename2) if f)
        what = exc.strerror or str(exc) or type(exc).__name__
        return f"{where} {what}" if where else what
    if isinstance(exc, MemoryError):
        return "out of memory"
    return f"{type(exc).__name__}: {exc} (a bug? rerun with --debug and report the traceback)"


def main(argv: Optional[List[str]] = None) -> int:
    """Run the command line; returns the exit status."""
    args_list = list(sys.argv[1:] if argv is None else argv)
    _safe_streams()
    os.environ.setdefault("OPENCV_LOG_LEVEL", "ERROR")  # OpenCV's own [ WARN ] lines stay off stderr
    if chosen_command(args_list) == "run" and "numpy" not in sys.modules:
        # the daemon is one thread of work: OpenBLAS would start a spinning thread per core at numpy's import
        os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    paused_gc = chosen_command(args_list) == "run" and gc.isenabled()
    if chosen_command(args_list) == "run" and threading.current_thread() is threading.main_thread():
        _signals.install_early()  # before the heavy imports: a SIGHUP now must not end the daemon
    if paused_gc:  # start-up makes ~30k objects that live for the run: no collections (66, ~3 % of it) while
        gc.disable()  # they are made; the daemon freezes them after its first frame and collects again
    try:
        return _run(args_list)
    except KeyboardInterrupt:  # Ctrl-C while the command's modules still load (before it runs): no traceback
        return EXIT_INTERRUPTED
    finally:
        if paused_gc:
            gc.enable()


def _run(args_list: List[str]) -> int:
    parser = build_parser(args_list)
    try:
        args = parser.parse_args(args_list)
    except BrokenPipeError:  # --help | head
        _silence_stdout()
        return 0
    except OSError as exc:  # --help > /dev/full
        print(f"rangebearing: error: {describe_error(exc)}", file=sys.stderr, flush=True)
        return EXIT_ERROR
    debug = getattr(args, "debug", False) or os.environ.get("RANGEBEARING_DEBUG", "") not in ("", "0")
    logging.basicConfig(
        level=logging.DEBUG if getattr(args, "verbose", False) else logging.INFO,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
        stream=sys.stderr,
    )
    try:
        return int(args.func(args) or 0)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        _silence_stdout()
        return 0
    except Exception as exc:
        if debug:
            raise
        print(f"rangebearing: error: {describe_error(exc)}", file=sys.stderr, flush=True)
        return EXIT_CONFIG if isinstance(exc, ConfigError) else EXIT_ERROR


def _safe_streams() -> None:
    """stdout and stderr that any text goes to: /dev/null for a closed one (``>&-``: Python makes it None);
    a character the stream's encoding lacks ("±", "°" on an ASCII console) is replaced, never an error.
    """
    for name in ("stdout", "stderr"):
        stream = getattr(sys, name)
        if stream is None:
            setattr(sys, name, open(os.devnull, "w", encoding="utf-8"))  # noqa: SIM115  (for the process's life)
        elif callable(getattr(stream, "reconfigure", None)) and getattr(stream, "errors", "") == "strict":
            with contextlib.suppress(ValueError, OSError):  # a stream that cannot change: as it is
                stream.reconfigure(errors="replace")


def _silence_stdout() -> None:
    """The reader (``| head``) went away: point stdout at /dev/null so the final flush is quiet."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


if __name__ == "__main__":
    sys.exit(main())
