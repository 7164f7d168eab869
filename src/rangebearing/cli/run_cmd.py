"""``rangebearing run``: the onboard daemon (foreground, logs to stderr for journald)."""

from __future__ import annotations

import argparse
import dataclasses
import logging
import os
import sys
from typing import TYPE_CHECKING, Any, Callable, Optional

from ..config import Config, check
from ..daemon.loop import Daemon
from ..daemon.sdnotify import Notifier
from ..errors import ConfigError
from ..net.protocol import decode_reading
from ..net.publisher import UdpPublisher
from ..sources.base import FrameSource
from ..sources.factory import open_source
from .common import add_config_arg, add_source_args, config_from_args, format_reading, source_from_args

if TYPE_CHECKING:
    from ..view.server import ViewServer

log = logging.getLogger("rangebearing.run")


def register(sub: Any) -> None:
    p = sub.add_parser(
        "run",
        help="run the daemon: camera → pipeline → UDP readings",
        description="Read frames, find every landmark, publish range and bearing over UDP. Runs in the "
        "foreground; SIGTERM/SIGINT stop it, SIGHUP reloads --config. Under systemd (Type=notify) it "
        "reports READY=1 after the first frame and pings the watchdog while frames flow.",
    )
    add_config_arg(p)
    add_source_args(p)
    p.add_argument("--echo", action="store_true", help="print every reading sent, one line per frame")
    p.add_argument("--json", action="store_true", help="with --echo, print the datagrams as sent")
    p.add_argument("--check", action="store_true", help="validate the config and exit")
    p.set_defaults(func=run)


def source_opener(cfg: Config, sleep: Callable[[float], object]) -> FrameSource:
    return open_source(cfg.source, cfg.camera, sleep=sleep, in_place=True)  # the loop is done with each frame


def publisher_for(cfg: Config) -> UdpPublisher:
    """The UDP publisher; a destination that does not resolve yet is retried in the background."""
    return UdpPublisher(cfg.publish, logging.getLogger("rangebearing.publish"))


def reloader(args: argparse.Namespace) -> Optional[Callable[[], Config]]:
    """What SIGHUP means: re-read ``--config``, the command line's own source still winning."""
    if not args.config:
        return None

    def reload() -> Config:
        new = config_from_args(args)
        override = source_from_args(args, new.source)
        if override is not None:
            new = dataclasses.replace(new, source=override)
            check(new)
        return new

    return reload


def run(args: argparse.Namespace) -> int:
    cfg = config_from_args(args)
    if args.json and not (args.echo or cfg.daemon.echo):
        raise ConfigError(["--json only applies with --echo (print the datagrams as sent)"], "command line")
    override = source_from_args(args, cfg.source)
    if override is not None:
        cfg = dataclasses.replace(cfg, source=override)
        check(cfg)
    if args.check:
        pub = publisher_for(cfg)  # destinations resolve now, the multicast interface is up
        pending = pub.pending
        pub.close()
        if pending:  # `run` would start and keep retrying these; --check says so
            raise ConfigError([f"{p} (run would start without it and keep retrying)" for p in pending],
                              cfg.source_file)
        print(f"{cfg.source_file}: OK")
        return 0
    echo = None
    if args.echo or cfg.daemon.echo:
        echo = _echo_json if args.json else _echo_line
    view = start_view_for(cfg, cfg.daemon.view_host, cfg.daemon.view_port, cfg.daemon.view_fps, args.config)
    try:
        daemon = Daemon(
            cfg, source_opener, publisher_for, Notifier(), reload=reloader(args), echo=echo,
            view=view.hub if view else None,
        )
        daemon.install_signal_handlers()
        dests = ", ".join(f"{h}:{p}" for h, p in cfg.publish.unicast)
        if cfg.publish.multicast_group:
            dests += f", multicast {cfg.publish.multicast_group}:{cfg.publish.multicast_port}"
        log.info("starting: source %s, publishing to %s", cfg.source.kind, dests or "nowhere")
        status = daemon.run()
    finally:
        if view is not None:
            view.close()
    if daemon.guard.wedged:  # a capture call never returned: its thread would hold the interpreter's exit
        log.warning("a capture call is still blocked in the camera stack; leaving without waiting for it")
        logging.shutdown()
        sys.stdout.flush()
        os._exit(status)
    return status


def start_view_for(
    cfg: Config, host: str, port: int, max_fps: float, config_file: Optional[str]
) -> Optional[ViewServer]:
    """The live web page for this config, or None when ``port`` is 0 (off)."""
    if not port:
        return None
    from ..view.app import start_view  # the HTTP server is loaded only when asked for

    return start_view(cfg.detection, cfg.camera, cfg.landmark, host, port, max_fps, config_file)


def _echo_json(payload: bytes) -> None:
    sys.stdout.write(payload.decode("utf-8") + "\n")
    sys.stdout.flush()


def _echo_line(payload: bytes) -> None:
    sys.stdout.write(format_reading(decode_reading(payload)) + "\n")
    sys.stdout.flush()
