"""``rangebearing replay``: run the pipeline over recorded frames; readings, JSON Lines, accuracy."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any, Dict, List, Tuple, Union

import cv2

from ..core.guarded import process_or_skip
from ..core.pipeline import Pipeline
from ..core.types import Landmark
from ..errors import FrameError, OutputError, SourceError
from ..evaluation.annotate import annotate
from ..evaluation.identity import format_id_report, id_report
from ..evaluation.match import accuracy, format_report
from ..net.protocol import landmark_fields
from ..sources.recorded import count_recorded, iter_recorded
from .common import add_config_arg, aligned_truth, config_from_args, describe, progress
from .outputs import AtomicText, check_output_dir, check_output_file, write_bytes_atomic


def register(sub: Any) -> None:
    p = sub.add_parser(
        "replay",
        help="run the pipeline over recorded frames",
        description="Run the pipeline over a directory of images (sorted by name), a video file or an "
        "MCAP recording (its /camera/image frames). Prints one line of readings per frame; --truth adds "
        "an accuracy report (for a video or MCAP file its frame column is the 0-based frame position, "
        "or for MCAP the frame's capture timestamp in integer Unix nanoseconds), and with --track and a "
        "truth that names each landmark's robot (synth's robot column), a track-id report (id switches, returns).",
    )
    p.add_argument("path", help="directory of .png/.jpg/.jpeg/.bmp images, a video file, or FILE.mcap")
    add_config_arg(p)
    p.add_argument("--out", metavar="FILE", help="write JSON Lines, one object per frame")
    p.add_argument("--annotate", metavar="DIR", help="write each frame with bands, centroids, range and bearing drawn")
    p.add_argument("--truth", metavar="FILE", help="CSV frame,range_m,bearing_rad: print an accuracy report")
    p.add_argument("--track", action="store_true", help="treat the frames as a sequence and track landmarks")
    p.add_argument("-q", "--quiet", action="store_true", help="do not print a line per frame")
    p.add_argument("--overwrite", action="store_true",
                   help="replace an existing --out file and write into a non-empty --annotate folder "
                        "(never over the frames, the truth or the config)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    cfg = config_from_args(args)
    truth = aligned_truth(args.path, args.truth) if args.truth else None
    pipe = Pipeline(cfg.pipeline, track=args.track)
    path = Path(args.path)
    is_video = path.is_file()  # a video or an MCAP recording: frames are named by position
    inputs = (args.path, args.truth, getattr(args, "config", None))
    if args.out:  # checked before anything is written: never over an input, never over a file unasked
        check_output_file(args.out, "--out", inputs, args.overwrite)
    ann_dir = check_output_dir(args.annotate, "--annotate", inputs, args.overwrite) if args.annotate else None
    out = AtomicText(args.out) if args.out else None
    evaluated: List[Tuple[str, Tuple[Landmark, ...], list]] = []
    bad = done = 0
    interrupted = False
    # the bar shares the terminal with the per-frame lines only when those go elsewhere (-q, or piped)
    bar = None if (args.quiet or not sys.stdout.isatty()) else False
    try:
        reasons: Dict[str, str] = {}
        for name, image in progress(iter_recorded(path, reasons), count_recorded(path), "replay", bar):
            done += 1
            try:
                if image is None:
                    why = reasons.pop(name, "")
                    raise FrameError(f"unreadable image: {why}" if why else "unreadable image")
                result = process_or_skip(pipe, image)
            except FrameError as exc:  # a bad frame, or a detector defect on it (DetectorFault): skipped, counted
                bad += 1
                print(f"{name}: skipped: {exc}", file=sys.stderr)
                continue
            key: Union[str, int] = int(name) if is_video else name
            if out:
                rec = {
                    "frame": key,
                    "landmarks": [landmark_fields(lm) for lm in result.landmarks],
                    "tracked": result.tracked,
                }
                out.write(json.dumps(rec, separators=(",", ":")) + "\n")
            if not args.quiet:
                print(f"{name}: " + (" | ".join(describe(lm) for lm in result.landmarks) or "-"), flush=True)
            if ann_dir:
                stem = Path(name).stem if not is_video else f"{int(name):06d}"
                ok, png = cv2.imencode(".png", annotate(image, result))
                if not ok:
                    raise OutputError(f"--annotate: cannot encode {stem}.png")
                write_bytes_atomic(ann_dir / f"{stem}.png", png.tobytes())
            if truth is not None:
                evaluated.append((name, result.landmarks, truth.get(name, [])))
    except KeyboardInterrupt:
        interrupted = True
        what = f"; {args.out} holds them" if args.out else ""
        print(f"\nreplay: interrupted after {done} frames{what}", file=sys.stderr)
    finally:
        if out:
            out.close()  # renamed into place: the lines so far, also when interrupted
    if bad:
        print(f"{bad} frame(s) skipped (unreadable, or the detector failed on them)", file=sys.stderr)
    if truth is not None:
        if not evaluated:
            raise SourceError(f"no frames of {path} could be evaluated")
        report, _ = accuracy(evaluated)
        print(format_report(report) + (f"\n(the first {len(evaluated)} frames only)" if interrupted else ""))
        if pipe.ids and any(t.robot is not None for _, _, rows in evaluated for t in rows):
            print(format_id_report(id_report((found, rows) for _, found, rows in evaluated)))
    return 130 if interrupted else 0
