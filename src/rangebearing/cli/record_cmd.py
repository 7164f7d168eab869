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

from .. import _signals
from ..config import Config, check
from ..core.guarded import process_or_skip
from ..core.pipeline import Pipeline
from ..errors import ConfigError, FrameError, OutputError, ProtocolError, RangeBearingError
from ..net.protocol import encode_reading, wire_time_ns
from ..sources.base import Frame
from ..sources.factory import open_source
from .common import (
    add_config_arg,
    add_quiet_arg,
    add_source_args,
    config_from_args,
    positive,
    progress,
    quiet_or_auto,
    source_from_args,
)
from .listen_cmd import MAX_WAIT_S
from .outputs import check_output_dir, check_output_file, write_bytes_atomic


def register(sub: Any) -> None:
    p = sub.add_parser(
        "record",
        help="save frames from a source as numbered images or one MCAP file",
        description="Save frames from the configured (or --source) camera as 000000.png, 000001.png, … "
        "for later 'replay' and 'calibrate', or, with --out FILE.mcap, into one MCAP file that "
        "Foxglove opens (frames as foxglove.CompressedImage, intrinsics as foxglove.CameraCalibration, "
        "with --readings also what the pipeline saw, on /rangebearing/readings).",
    )
    p.add_argument("--out", required=True, metavar="DIR|FILE.mcap", help="directory to write frames into, "
                   "or an MCAP file (needs the mcap extra)")
    p.add_argument("--readings", action="store_true",
                   help="with an MCAP --out: also run the pipeline and record each frame's reading")
    limit = p.add_mutually_exclusive_group(required=True)
    # 0, -1 or nan recorded nothing and exited 0: a command-line error
    limit.add_argument("--frames", type=positive(int, "number of frames"), metavar="N", help="stop after N frames")
    limit.add_argument("--seconds", type=positive(float, "number of seconds", most=MAX_WAIT_S), metavar="S",
                       help="stop after S seconds")
    p.add_argument("--format", choices=("png", "jpg"), default="png", help="image format (default png, lossless)")
    p.add_argument("--overwrite", action="store_true", help="write into a --out folder that is not empty")
    add_config_arg(p)
    add_source_args(p)
    add_quiet_arg(p)
    p.set_defaults(func=run)


class _Mcap:
    """One MCAP file: frames stamped with their capture time, the intrinsics, optionally readings."""

    def __init__(self, out: Path, args: argparse.Namespace, cfg: Config) -> None:
        from ..recording.mcap_writer import McapRecorder

        self.rec = McapRecorder(out, image_format="jpeg" if args.format == "jpg" else "png")
        self.rec.write_calibration(cfg.camera, time.time_ns())
        self.robot = cfg.publish.robot_id
        self.pipe = Pipeline(cfg.pipeline) if args.readings else None

    def add(self, frame: Frame, n: int) -> None:
        t_unix = time.time() - (time.monotonic_ns() - frame.t_mono_ns) / 1e9
        t_ns = wire_time_ns(t_unix)  # the µs a reading's t keeps, so both line up
        self.rec.write_image(frame.image, t_ns, frame.index)
        if self.pipe is not None:
            try:
                landmarks = process_or_skip(self.pipe, frame.image).landmarks
                self.rec.write_reading(encode_reading(self.robot, n, t_unix, landmarks), t_ns)
            except (FrameError, ProtocolError) as exc:  # a detector defect too (DetectorFault): the image is kept
                print(f"no reading for frame {n}: {exc}", file=sys.stderr)

    def close(self) -> None:
        self.rec.close()


def run(args: argparse.Namespace) -> int:
    cfg = config_from_args(args)
    src_cfg = source_from_args(args, cfg.source) or cfg.source
    check(dataclasses.replace(cfg, source=src_cfg))
    from_files = src_cfg.kind == "recorded"
    if from_files:  # every file, in order, under its own name: frames still match their truth
        src_cfg = dataclasses.replace(src_cfg, fps=0.0)
    inputs = (src_cfg.path if from_files else None, getattr(args, "config", None))
    to_mcap = str(args.out).lower().endswith(".mcap")
    if args.readings and not to_mcap:
        raise ConfigError(["--readings needs an MCAP --out (FILE.mcap)"], "command line")
    if to_mcap:
        out = check_output_file(args.out, "--out", inputs, args.overwrite)
    else:
        out = check_output_dir(args.out, "--out", inputs, args.overwrite, create=False)
    stop = threading.Event()
    _signals.handle({signal.SIGINT: stop.set, signal.SIGTERM: stop.set})  # not stop.set in a handler: _signals.Relay
    source = open_source(src_cfg, cfg.camera, sleep=stop.wait)  # a source that fails leaves no --out behind
    try:
        mcap = _Mcap(out, args, cfg) if to_mcap else None
        if mcap is None:
            out.mkdir(parents=True, exist_ok=True)
    except (OSError, RangeBearingError) as exc:
        source.close()
        if isinstance(exc, RangeBearingError):
            raise
        raise OutputError(f"--out: cannot create {out}: {exc.strerror or exc}") from None
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
            if mcap is not None:
                mcap.add(frame, n)
                n += 1
                continue
            stem = Path(frame.name).stem if from_files and frame.name and not frame.name.isdigit() else f"{n:06d}"
            ok, data = cv2.imencode(f".{args.format}", frame.image)
            if not ok:
                raise OutputError(f"cannot encode frame {n} as {args.format}")
            write_bytes_atomic(out / f"{stem}.{args.format}", data.tobytes())
            n += 1
        dropped = source.dropped
    finally:
        source.close()
        if mcap is not None:
            mcap.close()
    why = " (stopped by a signal)" if stop.is_set() else ""
    print(f"recorded {n} frames to {out}{why} ({dropped} dropped by the source, {bad} bad)")
    return 0
