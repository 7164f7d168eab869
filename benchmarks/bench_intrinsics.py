"""How well ``rangebearing intrinsics`` recovers a known camera, and the presets against the published figures.

Renders chessboard views (``synth/chessboard.py``: exact OpenCV distortion,
3×3 supersampling) through three cameras, runs the same corner finder and fit
as the command, and prints the focal-length errors and the worst corner
reprojection error. Run: ``python benchmarks/bench_intrinsics.py``.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from rangebearing.core.camera_models import PRESETS, preset_intrinsics
from rangebearing.core.charuco import charuco_board, find_charuco
from rangebearing.core.intrinsics import board_points, find_corners, fit_intrinsics, fit_views
from rangebearing.core.types import CameraIntrinsics
from rangebearing.synth.charuco import random_charuco_views
from rangebearing.synth.chessboard import camera_matrix, random_views

CAMERAS = {
    "pi-v1-like, barrel": CameraIntrinsics(640, 480, 634.0, 634.0, 319.5, 239.5, (-0.15, 0.03, 0.0, 0.0, 0.0)),
    "off-centre, strong": CameraIntrinsics(640, 480, 560.0, 556.0, 322.0, 236.5, (-0.28, 0.09, 0.001, -0.0008, 0.0)),
    "pi-v2-like, mild": CameraIntrinsics(640, 480, 529.6, 529.6, 319.5, 239.5, (0.05, -0.1, 0.0, 0.0, 0.0)),
}


def recovery(cam: CameraIntrinsics, views: int = 15, seed: int = 11) -> str:
    shots = random_views(cam, 9, 6, 0.025, views, seed=seed)
    found = [find_corners(cv2.cvtColor(v.image, cv2.COLOR_BGR2GRAY), 9, 6) for v in shots]
    fit = fit_intrinsics([c for c in found if c is not None], 9, 6, 0.025, (cam.width_px, cam.height_px))
    k, d, obj = camera_matrix(fit.camera), np.asarray(fit.camera.distortion), board_points(9, 6, 0.025)
    worst = 0.0
    for v, rv, tv in zip(shots, fit.rvecs, fit.tvecs):
        proj, _ = cv2.projectPoints(obj, np.array(rv), np.array(tv), k, d)
        worst = max(worst, float(np.abs(proj.reshape(-1, 2) - v.corners_px).max()))
    fx_err = 100 * (fit.camera.fx_px / cam.fx_px - 1)
    fy_err = 100 * (fit.camera.fy_px / cam.fy_px - 1)
    return (f"fx {fx_err:+.3f} %  fy {fy_err:+.3f} %  cx {fit.camera.cx_px - cam.cx_px:+.2f} px  "
            f"cy {fit.camera.cy_px - cam.cy_px:+.2f} px  RMS {fit.rms_px:.3f} px  worst true corner {worst:.3f} px")


def charuco_recovery(cam: CameraIntrinsics, views: int = 15, seed: int = 11) -> str:
    board = charuco_board(10, 7, 0.025, 0.018, "4X4_50")
    shots = random_charuco_views(cam, board, views, seed=seed)
    found = [f for f in (find_charuco(cv2.cvtColor(v.image, cv2.COLOR_BGR2GRAY), board) for v in shots) if f]
    fit = fit_views([f[0] for f in found], [f[1] for f in found], (cam.width_px, cam.height_px))
    fx_err, fy_err = 100 * (fit.camera.fx_px / cam.fx_px - 1), 100 * (fit.camera.fy_px / cam.fy_px - 1)
    return (f"fx {fx_err:+.3f} %  fy {fy_err:+.3f} %"
            f"  RMS {fit.rms_px:.3f} px  ({len(found)} views, {sum(len(f[0]) for f in found)} corners)")


def main() -> None:
    print("intrinsics recovered from 15 rendered 9x6 chessboard views at 640x480:")
    for name, cam in CAMERAS.items():
        print(f"  {name:20s} {recovery(cam)}")
    print("the same from 15 ChArUco 10x7 views (4X4_50, some partly outside the frame):")
    for name, cam in CAMERAS.items():
        print(f"  {name:20s} {charuco_recovery(cam)}")
    print("\npresets (published pixel pitch and focal length); at 640x480 a 16:9 sensor loses its sides:")
    for name, p in PRESETS.items():
        full = preset_intrinsics(name, p.array_w_px, p.array_h_px)
        vga = preset_intrinsics(name, 640, 480)
        pub = f"{p.hfov_deg_published:.1f}°" if p.hfov_deg_published else "n/a"
        print(f"  {name:11s} {p.focal_mm:5.2f} mm / {p.pixel_um:.2f} µm = {p.focal_px:8.1f} px full width "
              f"({p.array_w_px}), {vga.fx_px:6.1f} px at 640x480; HFOV {math.degrees(full.hfov_rad):5.1f}° "
              f"(published {pub})")


if __name__ == "__main__":
    main()
