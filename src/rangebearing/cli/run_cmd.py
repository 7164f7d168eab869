"""``rangebearing run``: the onboard daemon (foreground, logs to stderr for journald)."""

from __future__ import annotations

import argparse
import dataclasses
import logging
import os
import sys
from typing import TYPE_CHECKING, Any, Callable, Optional

from ..allocator import keep_freed_buffers, one_worker
from ..config import Config, check
from ..daemon.capture import SourceUnusable
from ..daemon.loop import Daemon
from ..daemon.sdnotify import Notifier
from ..errors import CameraError, ConfigError, SourceError
from ..net.fanout import FanOut, Shared
from ..net.protocol import decode_reading
from ..net.publisher import Publisher, UdpPublisher
from ..sources.base import FrameSource
from ..sources.factory import open_source
from .common import add_config_arg, add_source_args, config_from_args, format_reading, positive, source_from_args

if TYPE_CHECKING:
    from ..view.server import ViewServer

log = logging.getLogger("rangebearing.run")
MIN_RECORD_MB = 1.0  # a 640×480 JPEG frame with its reading is ~50-100 kB


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
    p.add_argument("--record", metavar="FILE.mcap", default=None,
                   help="also record every frame and reading into an MCAP file (needs the mcap extra; "
                        "a writer thread, never slowing or stopping the loop)")
    p.add_argument("--record-max-mb", type=positive(float, "number of megabytes"), default=None, metavar="N",
                   help="rotate at N MB: the full file becomes FILE.1.mcap (replacing the previous one), "
                        "so at most ~2N MB of the latest frames are kept (default: no limit)")
    p.add_argument("--record-format", choices=("jpeg", "png"), default="jpeg",
                   help="how recorded frames are stored (default jpeg; png is lossless and ~5x larger)")
    p.set_defaults(func=run)





def recorder_for(args: argparse.Namespace, cfg: Config) -> Optional[Any]:
    """The MCAP writer thread for ``--record``, or None."""
    if args.record is None:
        if args.record_max_mb is not None:
            raise ConfigError(["--record-max-mb needs --record FILE.mcap"], "command line")
        return None
    if args.record_max_mb is not None and args.record_max_mb < MIN_RECORD_MB:  # a file rotated at every frame
        raise ConfigError([f"--record-max-mb: at least {MIN_RECORD_MB:g} (MB), got {args.record_max_mb:g}: a smaller "
                           "file holds no frame whole, and rotating at each one keeps none"], "command line")
    from ..recording.background import BackgroundRecorder
    from .outputs import check_output_file

    # never over what the daemon reads: --record onto its --config replaced the config with an MCAP file
    inputs = (getattr(args, "config", None), cfg.source.path if cfg.source.kind == "recorded" else None)
    check_output_file(args.record, "--record", inputs, overwrite=True)

    max_bytes = None if args.record_max_mb is None else int(args.record_max_mb * 1e6)
    return BackgroundRecorder(args.record, cfg.camera, max_bytes=max_bytes, image_format=args.record_format,
                              logger=logging.getLogger("rangebearing.record"))


def source_opener(cfg: Config, sleep: Callable[[float], object]) -> FrameSource:
    try:
        return open_source(cfg.source, cfg.camera, sleep=sleep, in_place=True)  # the loop is done with each frame
    except SourceError as exc:  # a recording that is missing or unreadable stays so: no minute of retries
        if cfg.source.kind in ("recorded", "synthetic") and not isinstance(exc, CameraError):
            raise SourceUnusable(str(exc)) from None
        raise


def publisher_for(cfg: Config) -> UdpPublisher:
    """The UDP publisher; a destination that does not resolve yet is retried in the background."""
    return UdpPublisher(cfg.publish, logging.getLogger("rangebearing.publish"))


class Publishers:
    """UDP, plus Zenoh when ``publish.zenoh.enabled``; a reload that leaves the Zenoh settings
    and the robot id alone keeps the same Zenoh session, so presence does not flicker."""

    def __init__(self) -> None:
        self._zenoh: Optional[Shared] = None
        self._zenoh_for: Any = None

    def __call__(self, cfg: Config) -> Publisher:
        udp = publisher_for(cfg)
        z = cfg.publish.zenoh
        if not z.enabled:
            return udp
        wanted = (z, cfg.publish.robot_id)
        try:
            if self._zenoh is None or self._zenoh_for != wanted:
                from ..net.zenoh_transport import ZenohPublisher, ZenohSettings

                zp = ZenohPublisher(cfg.publish.robot_id, ZenohSettings.from_config(z), key=z.key, wait_s=1.0,
                                    logger=logging.getLogger("rangebearing.publish"))
                self._zenoh, self._zenoh_for = Shared(zp), wanted
            return FanOut([udp, self._zenoh.handle()])
        except BaseException:
            udp.close()
            raise


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
        if cfg.publish.zenoh.enabled:  # Zenoh itself accepts the endpoints (needs the extra)
            from ..net.zenoh_transport import ZenohSettings

            ZenohSettings.from_config(cfg.publish.zenoh).zenoh_config()
        print(f"{cfg.source_file}: OK")
        return 0
    echo = None
    if args.echo or cfg.daemon.echo:
        echo = _echo_json if args.json else _echo_line
    keep_freed_buffers()  # a frame's large buffers stay in the heap: no page faults for them every frame
    one_worker()  # OpenCV's thread pool off: waking it for 640×480 calls cost ~4 % more CPU a frame, per core
    view = start_view_for(cfg, cfg.daemon.view_host, cfg.daemon.view_port, cfg.daemon.view_fps, args.config)
    recorder = None
    try:
        recorder = recorder_for(args, cfg)
        daemon = Daemon(
            cfg, source_opener, Publishers(), Notifier(), reload=reloader(args), echo=echo,
            view=view.hub if view else None, recorder=recorder, freeze_gc=True,
        )
        daemon.install_signal_handlers()
        dests = ", ".join(f"{h}:{p}" for h, p in cfg.publish.unicast)
        if cfg.publish.multicast_group:
            dests += f", multicast {cfg.publish.multicast_group}:{cfg.publish.multicast_port}"
        z = cfg.publish.zenoh
        if z.enabled:
            dests += f", zenoh {z.mode} {z.key.replace('{robot}', cfg.publish.robot_id)}"
        log.info("starting: source %s, publishing to %s", cfg.source.kind, dests or "nowhere")
        status = daemon.run()
    finally:
        if view is not None:
            view.close()
        if recorder is not None:
            recorder.close()  # the daemon closed it already, unless it never started
            c = recorder.counts
            log.info("recorded %d frames and %d readings to %s (%d dropped, %d rotations)%s", c["frames"],
                     c["readings"], args.record, c["dropped"], c["rotations"],
                     f"; stopped early: {recorder.failed}" if recorder.failed else "")
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
