"""``rangebearing view``: the capture loop with its live web page, for looking and tuning (no readings sent)."""

from __future__ import annotations

import argparse
import dataclasses
import logging
import sys
from typing import Any

from ..config import Config, check
from ..daemon.loop import Daemon
from ..daemon.sdnotify import Notifier
from ..errors import ConfigError
from .common import add_config_arg, add_source_args, config_from_args, source_from_args
from .run_cmd import publisher_for, reloader, source_opener

log = logging.getLogger("rangebearing.view")


def register(sub: Any) -> None:
    p = sub.add_parser(
        "view",
        help="serve a live web page of what the camera sees, with the detections and threshold controls",
        description="Run the capture loop and serve a web page with the camera stream and the detections "
        "drawn, a bird's-eye plot of the neighbours, the loop's figures, the red and blue masks, and threshold "
        "controls that change detection live and can be saved to --config (the old file kept as FILE.bak). "
        "Listens on loopback: from another machine use an SSH tunnel, e.g. ssh -L 8080:127.0.0.1:8080 pi@robot. "
        "No readings are sent unless --publish is given. See docs/view.md.",
    )
    add_config_arg(p)
    add_source_args(p)
    p.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1: this machine only)")
    p.add_argument("--port", type=int, default=8080, help="port to listen on (default 8080; 0 picks a free one)")
    p.add_argument("--view-fps", type=float, default=None, metavar="FPS",
                   help="frames drawn and sent per second while a browser watches (default: daemon.view_fps, 10)")
    p.add_argument("--publish", action="store_true", help="also publish readings as 'run' does")
    p.set_defaults(func=run)


class _Silent:
    """A publisher that sends nothing: ``view`` only looks, unless told to ``--publish``."""

    def send(self, payload: bytes) -> None:
        pass

    def close(self) -> None:
        pass


def run(args: argparse.Namespace) -> int:
    cfg: Config = config_from_args(args)
    override = source_from_args(args, cfg.source)
    if override is not None:
        cfg = dataclasses.replace(cfg, source=override)
        check(cfg)
    if not 0 <= args.port <= 65535:
        raise ConfigError([f"--port: {args.port} is outside [0, 65535]"], "command line")
    view_fps = cfg.daemon.view_fps if args.view_fps is None else args.view_fps
    if not 0 < view_fps <= 60:
        raise ConfigError([f"--view-fps: {view_fps} is outside (0, 60]"], "command line")
    from ..view.app import start_view

    server = start_view(cfg.detection, cfg.camera, cfg.landmark, args.host, args.port, view_fps, args.config)
    try:
        print(f"rangebearing view: {server.url}  (Ctrl-C stops)", file=sys.stderr, flush=True)
        daemon = Daemon(
            cfg, source_opener, publisher_for if args.publish else (lambda _cfg: _Silent()), Notifier(),
            reload=reloader(args), view=server.hub,
        )
        daemon.install_signal_handlers()
        return daemon.run()
    finally:
        server.close()

