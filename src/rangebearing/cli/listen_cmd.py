"""``rangebearing listen``: print readings as they arrive, like ``ros2 topic echo``."""

from __future__ import annotations

import argparse
import io
import json
import signal
import sys
import threading
from typing import Any, Optional, TextIO

from ..config import DEFAULT_PORT
from ..errors import ConfigError, NoReadingError, SubscribeError
from ..net.client import Subscriber
from .common import DEFAULT_ZENOH_LISTEN, add_zenoh_args, format_reading, positive, settings_from_args

DESCRIPTION = """\
Listen for rangebearing readings and print one line per frame:

  zumo #1234 t=1732419876.123  2 landmarks: 0.412 m  +12.3° | 1.205 m  -4.0° (out of envelope)

Bearings are positive to the left of the camera's optical axis. Every daemon
sends a reading for every frame, so silence means no daemon is publishing here.
Exits 0 on Ctrl-C, on SIGTERM (with a one-line summary on stderr) or after
--count readings, 1 if --timeout passes in silence.

With --zenoh, subscribe over Eclipse Zenoh instead of UDP (the same readings;
needs the zenoh extra): by default as a peer listening on tcp/127.0.0.1:7447
for daemons that dial it, or --connect to a router or a robot.
"""


MAX_WAIT_S = 1e9  # ~32 years: any wait a user means; 1e300 s overflowed time_t


def port_number(text: str) -> int:
    """An argparse ``type``: a UDP port, 0-65535."""
    try:
        port = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a port number") from None
    if not 0 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"{port} is not in 0-65535")
    return port


def register(subparsers: Any) -> None:
    """Add the ``listen`` subcommand to a ``parser.add_subparsers()`` object."""
    p = subparsers.add_parser(
        "listen",
        help="print readings published by rangebearing daemons",
        description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--port", type=port_number, default=DEFAULT_PORT,
                   help=f"UDP port to listen on (default {DEFAULT_PORT})")
    p.add_argument(
        "--host",
        default="127.0.0.1",
        help="local address for unicast (default 127.0.0.1; 0.0.0.0 hears robots on the network)",
    )
    p.add_argument(
        "--group", default=None, metavar="G", help="join this IPv4 multicast group instead, e.g. 239.255.47.80"
    )
    p.add_argument(
        "--interface", default=None, metavar="I", help="address of the interface to join --group on (default 127.0.0.1)"
    )
    p.add_argument("--json", action="store_true", help="print each datagram's raw JSON instead")
    p.add_argument("--count", type=positive(int), default=None, metavar="N", help="exit 0 after N readings")
    p.add_argument(
        "--timeout",
        type=positive(float, most=MAX_WAIT_S),
        default=None,
        metavar="S",
        help="exit 1 if no reading arrives for S seconds (default: wait forever)",
    )
    p.add_argument("--zenoh", action="store_true", help="subscribe over Zenoh instead of UDP (see below)")
    add_zenoh_args(p, DEFAULT_ZENOH_LISTEN)
    p.set_defaults(func=run)


def _one_line_json(data: bytes) -> str:
    text = data.decode("utf-8").strip()
    if not (text.isascii() and text.isprintable()):
        # Pretty-printed by another writer, or raw non-ASCII (C1 controls, bidi overrides):
        # one line of ASCII, every other character as a JSON \u escape.
        text = json.dumps(json.loads(text), separators=(",", ":"), ensure_ascii=True)
    return text


class _Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``, ``systemctl stop``, ``timeout``): ends listening as Ctrl-C does."""


class _Shown:
    """How many readings have been printed (read by the SIGTERM summary)."""

    def __init__(self) -> None:
        self.count = 0


def _on_sigterm(signum: int, frame: Any) -> None:
    raise _Terminated()


def echo(
    sub: Any,
    out: TextIO,
    as_json: bool = False,
    count: Optional[int] = None,
    timeout_s: Optional[float] = None,
    where: Optional[str] = None,
    shown_so_far: Optional[_Shown] = None,
) -> int:
    """Print readings from ``sub`` to ``out``; 0 after ``count`` readings.

    Raises
    ------
    NoReadingError
        Nothing valid arrived within ``timeout_s``.
    """
    tally = shown_so_far if shown_so_far is not None else _Shown()
    tally.count = 0
    while count is None or tally.count < count:
        got = sub.recv_datagram(timeout_s)
        if got is None:
            where = where or f"{sub.group or sub.address[0]}:{sub.port}"
            raise NoReadingError(
                f"no reading arrived on {where} within {timeout_s:g} s"
                + (f" ({sub.dropped} invalid datagrams dropped)" if sub.dropped else "")
            )
        reading, data = got
        line = _one_line_json(data) if as_json else format_reading(reading)
        print(line, file=out, flush=True)
        tally.count += 1
    return 0


def run(args: argparse.Namespace) -> int:
    """Run ``rangebearing listen`` with parsed arguments; returns the exit status."""
    if args.interface is not None and not args.group:
        raise ConfigError(["--interface only applies with --group"], "command line")
    where = f"{args.group or args.host}:{args.port}"
    if args.zenoh:
        from ..net.zenoh_client import ZenohSubscriber

        sub: Any = ZenohSubscriber(args.key, settings_from_args(args, DEFAULT_ZENOH_LISTEN), presence=False)
        where = f"zenoh {args.key}"
    else:
        try:
            sub = Subscriber(port=args.port, host=args.host, group=args.group,
                             interface=args.interface or "127.0.0.1")
        except SubscribeError:
            raise
        except OSError as exc:
            raise SubscribeError(f"cannot listen on {where}: {exc.strerror or exc}") from None
    if isinstance(sys.stdout, io.TextIOWrapper):  # a terminal that cannot show a character gets an escape
        sys.stdout.reconfigure(errors="backslashreplace")
    tally = _Shown()
    handles_term = threading.current_thread() is threading.main_thread()  # handlers live in the main thread only
    previous = signal.signal(signal.SIGTERM, _on_sigterm) if handles_term else None
    try:
        with sub:
            return echo(sub, sys.stdout, args.json, args.count, args.timeout, where, tally)
    except _Terminated:  # `kill`, `timeout 10 rangebearing listen`: the readings so far were the point
        dropped = getattr(sub, "dropped", 0)
        print(
            f"rangebearing listen: terminated after {tally.count} readings on {where}"
            + (f" ({dropped} invalid datagrams dropped)" if dropped else ""),
            file=sys.stderr,
            flush=True,
        )
        return 0
    except KeyboardInterrupt:  # Ctrl-C is how a user ends listening: not a failure
        return 0
    finally:
        if handles_term:  # None: a handler set outside Python, which cannot be put back; the default stands in
            signal.signal(signal.SIGTERM, signal.SIG_DFL if previous is None else previous)
