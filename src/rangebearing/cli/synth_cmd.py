"""``rangebearing synth``: render synthetic frames with exact ground truth."""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from typing import Any, Iterator, Tuple

from ..core.types import CameraIntrinsics
from ..errors import OutputError
from ..synth.dataset import CAMERA_FILE, FORMATS, TRUTH_FILE, write_dataset
from ..synth.presets import PRESET_HELP, PRESETS
from .common import add_quiet_arg, progress, quiet_or_auto


def _size(text: str) -> Tuple[int, int]:
    w, sep, h = text.lower().partition("x")
    if not (sep and w.isdigit() and h.isdigit() and int(w) >= 16 and int(h) >= 16):
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT such as 640x480, got {text!r}")
    return int(w), int(h)


def _distortion(text: str) -> Tuple[float, float]:
    parts = text.split(",")
    try:
        k1, k2 = (float(p) for p in parts)
    except ValueError:
        msg = f"expected k1,k2 such as -0.2,0.05, got {text!r}"
        raise argparse.ArgumentTypeError(msg) from None
    if not all(abs(k) < 10 for k in (k1, k2)):
        raise argparse.ArgumentTypeError(f"coefficients out of range: {text!r}")
    return k1, k2


def _count(text: str) -> int:
    if not text.isdigit():
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got {text!r}")
    return int(text)


def _quality(text: str) -> int:
    if not text.isdigit() or not 1 <= int(text) <= 100:
        raise argparse.ArgumentTypeError(f"expected 1-100, got {text!r}")
    return int(text)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "synth",
        help="render synthetic frames with exact ground truth",
        description="Ray-trace camera frames of landmarks (and distractors) with known range and "
        "bearing. Writes 000000.png ... into DIR, truth.csv (frame,range_m,bearing_rad, then "
        "visible,red_visible,blue_visible: the fraction of the landmark and of each band in "
        "view, findable: 1 when both bands are >= 60 % visible, robot: an identity kept over a "
        "sequence; one row per landmark in view, none for an empty frame) and camera.yaml (the "
        "intrinsics, usable as --config). Presets: "
        + "; ".join(f"{k} = {v}" for k, v in PRESET_HELP.items()) + ".",
    )
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (created if missing)")
    p.add_argument("--frames", required=True, type=_count, metavar="N", help="number of frames")
    p.add_argument(
        "--seed", required=True, type=_count, metavar="S", help="random seed: the same seed gives the same frames"
    )
    p.add_argument("--preset", choices=PRESETS, default="paper", help="scene family (default: paper)")
    p.add_argument("--format", dest="fmt", choices=FORMATS, default="png", help="image format (default: png)")
    p.add_argument(
        "--jpeg-quality",
        type=_quality,
        default=90,
        metavar="Q",
        help="JPEG quality 1-100 for --format jpg (default: 90)",
    )
    p.add_argument(
        "--size",
        type=_size,
        metavar="WxH",
        help="image size; the default 640x480 camera scaled to the same field of view",
    )
    p.add_argument(
        "--distortion",
        type=_distortion,
        metavar="k1,k2",
        help="radial distortion (OpenCV k1, k2), e.g. --distortion=-0.2,0.05 "
        "(with '=' when k1 is negative); default none",
    )
    p.add_argument("--overwrite", action="store_true", help="replace frames and truth.csv already in DIR")
    add_quiet_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    camera = CameraIntrinsics()
    if args.size is not None:
        camera = camera.scaled(*args.size)
    if args.distortion is not None:
        camera = dataclasses.replace(camera, distortion=(*args.distortion, 0.0, 0.0, 0.0))
    start = time.perf_counter()
    done = [0]

    def counted(items: Iterator[Any]) -> Iterator[Any]:
        for item in progress(items, args.frames, "synth", quiet_or_auto(args)):
            yield item
            done[0] += 1

    try:
        truth = write_dataset(
            args.out, args.frames, args.seed, args.preset, args.fmt, args.jpeg_quality, camera,
            overwrite=args.overwrite, wrap=counted,
        )
    except FileExistsError as exc:
        raise OutputError(f"{exc} (--overwrite replaces them)") from None
    except KeyboardInterrupt:
        print(f"\nsynth: interrupted after {done[0]} of {args.frames} frames; {TRUTH_FILE} and {CAMERA_FILE} "
              f"in {args.out} cover exactly those", file=sys.stderr)
        return 130
    seconds = time.perf_counter() - start
    with_landmark = len({row.frame for row in truth})
    print(
        f"synth: {args.frames} {args.preset} frames ({camera.width_px}x{camera.height_px} "
        f"{args.fmt}, seed {args.seed}) in {args.out}: {len(truth)} landmarks "
        f"({sum(row.findable is not False for row in truth)} findable), "
        f"{args.frames - with_landmark} frames without one; {TRUTH_FILE}, {CAMERA_FILE}; "
        f"{seconds:.1f} s"
    )
    return 0
