"""``rangebearing record``: save frames from any source for later replay and calibration."""

from __future__ import annotations

import argparse
import dataclasses
import signal
import sys
import threading
import time
from pathlib import Path
from typing import Any, Iterator

import cv2

from ..config import check
from ..errors import FrameError, SourceError
from ..sources.factory import open_source
from .common import (
    add_config_arg,
    add_quiet_arg,
    add_source_args,
    config_from_args,
    progress,
    quiet_or_auto,
    source_from_args,
)


def register(sub: Any) -> None:
    p = sub.add_parser(
        "record",
        help="save frames from a source as numbered images",
        description="Save frames from the configured (or --source) camera as 000000.png, 000001.png, … "
        "for later 'replay' and 'calibrate'.",
    )
    p.add_argument("--out", required=True, metavar="DIR", help="directory to write frames into")
    limit = p.add_mutually_exclusive_group(required=True)
    limit.add_argument("--frames", type=int, metavar="N", help="stop after N frames")
    limit.add_argument("--seconds", type=float, metavar="S", help="stop after S seconds")
    p.add_argument("--format", choices=("png", "jpg"), default="png", help="image format (default png, lossless)")
    add_config_arg(p)
    add_source_args(p)
    add_quiet_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    cfg = config_from_args(args)
    src_cfg = source_from_args(args, cfg.source) or cfg.source
    check(dataclasses.replace(cfg, source=src_cfg))
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SourceError(f"cannot create {out}: {exc.strerror or exc}") from None
    stop = threading.Event()
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    source = open_source(src_cfg, cfg.camera, sleep=stop.wait)
    n = bad = 0
    t_end = time.monotonic() + args.seconds if args.seconds else None

    def frames() -> Iterator[Any]:
        nonlocal bad
        while not stop.is_set() and (args.frames is None or n < args.frames):
            if t_end is not None and time.monotonic() >= t_end:
                return
            try:
                frame = source.read()
            except FrameError as exc:
                bad += 1
                print(f"bad frame skipped: {exc}", file=sys.stderr)
                continue
            if frame is None:
                return
            yield frame

    try:
        for frame in progress(frames(), args.frames, "record", quiet_or_auto(args)):
            path = out / f"{n:06d}.{args.format}"
            if not cv2.imwrite(str(path), frame.image):
                raise SourceError(f"cannot write {path}")
            n += 1
        dropped = source.dropped
    finally:
        source.close()
    why = " (stopped by a signal)" if stop.is_set() else ""
    print(f"recorded {n} frames to {out}{why} ({dropped} dropped by the source, {bad} bad)")
    return 0
