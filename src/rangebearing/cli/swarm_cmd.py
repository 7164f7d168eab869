"""``rangebearing swarm``: a live view of every robot, who is alive and what each one sees."""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any, Callable, Optional, TextIO, Union

from ..errors import TransportError
from ..net.swarm import SwarmState, render
from .common import DEFAULT_ZENOH_LISTEN, add_zenoh_args, positive, settings_from_args
from .listen_cmd import MAX_WAIT_S, port_number

DESCRIPTION = """\
Show the whole swarm at a glance: one line per robot with its state (alive,
stale, gone), how many neighbours it sees, the nearest one's range and bearing,
its frame rate and the age of its last reading.

Over Zenoh (the default) presence comes from each daemon's liveliness token, so
a robot that stops or crashes shows as "gone" at once. On a terminal the table
is redrawn in place; piped, it prints join/leave lines and the table every
--interval seconds, each line stamped with the time.

  rangebearing swarm                                   # robots on this machine
  rangebearing swarm --listen tcp/0.0.0.0:7447         # robots dial this laptop
  rangebearing swarm --mode client --connect tcp/10.0.0.1:7447   # through a zenohd router
  rangebearing swarm --udp --port 47800                # plain UDP (no presence)
"""

DEFAULT_LISTEN = DEFAULT_ZENOH_LISTEN
CLEAR = "\x1b[H\x1b[2J"





def register(subparsers: Any) -> None:
    """Add the ``swarm`` subcommand."""
    p = subparsers.add_parser("swarm", help="live view of every robot's presence and readings",
                              description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_zenoh_args(p, DEFAULT_LISTEN)
    p.add_argument("--udp", action="store_true", help="hear plain UDP readings instead of Zenoh")
    p.add_argument("--port", type=port_number, default=None, help="UDP port with --udp (default 47800)")
    p.add_argument("--host", default="127.0.0.1", help="UDP address to bind with --udp (default 127.0.0.1)")
    seconds = positive(float, "number of seconds", most=MAX_WAIT_S)
    p.add_argument("--interval", type=seconds, default=None, metavar="S",
                   help="refresh every S seconds (default 0.5 on a terminal, 5 when piped)")
    p.add_argument("--duration", type=seconds, default=None, metavar="S", help="exit 0 after S seconds")
    p.set_defaults(func=run)


Source = Any  # a Subscriber or a ZenohSubscriber: recv(timeout_s), optional recv_presence()


def watch(
    sub: Source,
    out: TextIO,
    interval_s: float,
    duration_s: Optional[float] = None,
    live: bool = False,
    clock: Callable[[], float] = time.monotonic,
) -> int:
    """Fold readings and presence into a :class:`SwarmState` and print it every ``interval_s``."""
    state = SwarmState()
    start = clock()
    next_draw = start
    poll = getattr(sub, "recv_presence", None)
    while duration_s is None or clock() - start < duration_s:
        while poll is not None:
            ev = poll(0.0)
            if ev is None:
                break
            state.on_presence(ev.robot, ev.alive)
            if not live:
                print(f"{_stamp()} {ev.robot} {'joined' if ev.alive else 'left'}", file=out, flush=True)
        now = clock()
        if now >= next_draw:
            _draw(render(state.rows(now)), out, live)
            next_draw = now + interval_s
        wait = max(0.0, min(next_draw - clock(), 0.1))
        reading = sub.recv(wait)
        while reading is not None:
            state.on_reading(reading, clock())
            reading = sub.recv(0.0)
    _draw(render(state.rows(clock())), out, live)
    return 0


def _stamp() -> str:
    return time.strftime("%H:%M:%S")


def _draw(lines: list, out: TextIO, live: bool) -> None:
    if live:
        out.write(CLEAR + "\n".join(lines) + "\n")
    else:
        stamp = _stamp()
        out.write("".join(f"{stamp} {line}\n" for line in lines))
    out.flush()


def _open(args: argparse.Namespace) -> Union[Source, Any]:
    if args.udp:
        from ..config import DEFAULT_PORT
        from ..net.client import Subscriber

        port = DEFAULT_PORT if args.port is None else args.port
        try:
            return Subscriber(port=port, host=args.host)
        except OSError as exc:
            raise TransportError(f"cannot listen on {args.host}:{port}: {exc.strerror or exc}") from None
    from ..net.zenoh_client import ZenohSubscriber

    return ZenohSubscriber(args.key, settings_from_args(args, DEFAULT_LISTEN))


def run(args: argparse.Namespace) -> int:
    """Run ``rangebearing swarm``; returns the exit status."""
    live = sys.stdout.isatty()
    interval = args.interval or (0.5 if live else 5.0)
    sub = _open(args)
    try:
        return watch(sub, sys.stdout, interval, args.duration, live)
    except KeyboardInterrupt:
        return 0
    finally:
        sub.close()
