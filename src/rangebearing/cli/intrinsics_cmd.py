"""``rangebearing intrinsics``: camera intrinsics and distortion from chessboard frames."""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from pathlib import Path
from typing import Any, Dict, List, Tuple

import cv2
import numpy as np

from ..core.charuco import charuco_board, find_charuco
from ..core.intrinsics import board_points, find_corners, fit_views
from ..errors import CalibrationError
from ..sources.recorded import count_recorded, iter_recorded
from .common import add_config_arg, add_quiet_arg, config_from_args, progress, quiet_or_auto, save_config
from .outputs import check_config_out


def _board(text: str) -> Tuple[int, int]:
    c, sep, r = text.lower().partition("x")
    if not (sep and c.isdigit() and r.isdigit() and int(c) >= 3 and int(r) >= 3 and c != r):
        raise argparse.ArgumentTypeError(
            f"expected inner corners COLSxROWS such as 9x6 (unequal, each ≥ 3), got {text!r}"
        )
    return int(c), int(r)


def _square(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected millimetres such as 25, got {text!r}") from None
    if not 1 <= v <= 1000:
        raise argparse.ArgumentTypeError(f"square size {v} mm is out of range (1–1000)")
    return v


def register(sub: Any) -> None:
    p = sub.add_parser(
        "intrinsics",
        help="camera intrinsics and lens distortion from chessboard frames",
        description="Find a chessboard in each frame (OpenCV findChessboardCorners + cornerSubPix), "
        "check that the views cover the image and tilt both ways, fit fx, fy, cx, cy and distortion "
        "(cv2.calibrateCamera) and write a complete config with that camera section. Print a board "
        "(e.g. OpenCV's pattern.png, 10x7 squares = 9x6 inner corners), record 15-30 frames with "
        "'rangebearing record' while moving it over the whole image and tilting it.",
    )
    p.add_argument("frames", help="directory of images or a video file")
    p.add_argument("--board", required=True, type=_board, metavar="COLSxROWS",
                   help="chessboard: inner corners, e.g. 9x6; with --charuco: squares, e.g. 10x7")
    p.add_argument("--square-mm", required=True, type=_square, metavar="MM", help="side of one square (mm)")
    p.add_argument("--charuco", metavar="DICT", help="a ChArUco board with markers from this ArUco dictionary, "
                   "e.g. 4X4_50 (partial views count, so the frame's edges are easier to cover)")
    p.add_argument("--marker-mm", type=_square, metavar="MM", help="with --charuco: side of one marker (mm)")
    p.add_argument("--out", required=True, metavar="FILE", help="where to write the config (YAML)")
    p.add_argument("--k3", action="store_true", help="also fit k3 (wide-angle lenses such as pi-v3-wide)")
    add_config_arg(p)
    add_quiet_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    cfg = config_from_args(args)
    # fail now, not after the fit: a writable file (an existing one is kept as .bak), never one of the frames
    check_config_out(args.out, "--out", args.frames)
    cols, rows = args.board
    charuco = None
    if args.charuco:
        if args.marker_mm is None:
            raise CalibrationError("--charuco needs --marker-mm, the side of one marker")
        charuco = charuco_board(cols, rows, args.square_mm / 1000.0, args.marker_mm / 1000.0, args.charuco)
    obj = board_points(cols, rows, args.square_mm / 1000.0)
    path = Path(args.frames)
    views: List[np.ndarray] = []
    objs: List[np.ndarray] = []
    size = None
    seen = missed = 0
    try:
        reasons: Dict[str, str] = {}
        for name, image in progress(iter_recorded(path, reasons), count_recorded(path), "intrinsics",
                                    quiet_or_auto(args)):
            seen += 1
            if image is None:
                print(f"{name}: unreadable, skipped: {reasons.pop(name, 'no image')}", file=sys.stderr)
                continue
            h, w = image.shape[:2]
            if size is None:
                size = (w, h)
            elif size != (w, h):
                raise CalibrationError(f"{name} is {w}×{h}, the frames before it {size[0]}×{size[1]}")
            gray = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
            found = find_charuco(gray, charuco) if charuco is not None else find_corners(gray, cols, rows)
            if found is None:
                missed += 1
            elif charuco is not None:
                views.append(found[0])  # type: ignore[index]
                objs.append(found[1])  # type: ignore[index]
            else:
                views.append(found)  # type: ignore[arg-type]
                objs.append(obj)
    except KeyboardInterrupt:
        print(f"\ninterrupted after {seen} frames ({len(views)} with the board); nothing written", file=sys.stderr)
        return 130
    if size is None:
        raise CalibrationError(f"no readable frames in {path}")
    kind = f"ChArUco {cols}x{rows} ({sum(len(v) for v in views)} corners)" if charuco is not None else f"{cols}x{rows}"
    print(f"board {kind} found in {len(views)} of {seen} frames ({missed} without it)")
    fit = fit_views(views, objs, size, k3=args.k3)
    cam = fit.camera
    print(f"fx {cam.fx_px:.2f} px  fy {cam.fy_px:.2f} px  cx {cam.cx_px:.2f}  cy {cam.cy_px:.2f}  "
          f"({cam.width_px}x{cam.height_px}, horizontal field of view {math.degrees(cam.hfov_rad):.1f}°)")
    print("distortion k1 k2 p1 p2 k3: " + " ".join(f"{c:+.5f}" for c in cam.distortion))
    worst = int(np.argmax(fit.view_rms_px))
    print(f"reprojection error RMS {fit.rms_px:.3f} px (worst view {worst + 1}: {fit.view_rms_px[worst]:.3f} px)")
    if fit.rms_px > 1.0:
        print("warning: reprojection error above 1 px: blurred frames, a board that is not flat, or "
              "a wrong --board size", file=sys.stderr)
    save_config(
        dataclasses.replace(cfg, camera=cam),
        args.out,
        f"rangebearing config written by 'rangebearing intrinsics' from {args.frames}\n"
        f"{len(views)} chessboard views, reprojection RMS {fit.rms_px:.3f} px",
    )
    return 0
