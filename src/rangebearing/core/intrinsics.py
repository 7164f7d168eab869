"""Camera intrinsics from chessboard views: corner finding, coverage checks, the fit.

Arrays in, results out: the CLI reads the frames and writes the config.
Coverage is checked before fitting because a fit to views that all show the
board face-on in the middle of the frame converges to a focal length that is
wrong by percent while reporting a small reprojection error.
"""

from __future__ import annotations

import math
from typing import List, Optional, Sequence, Tuple, Union

import cv2
import numpy as np

from .._compat import frozen
from ..errors import CalibrationError
from .types import CameraIntrinsics

MIN_VIEWS = 8
MIN_CELLS_FRAC = 0.75  # of a 4×4 grid over the frame, the share that must hold a corner
MIN_TILT_DEG = 12.0
MIN_TILTED_VIEWS = 3
SUBPIX = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 60, 1e-4)


@frozen
class IntrinsicsFit:
    """The fitted camera, its RMS reprojection error (px) and each view's."""

    camera: CameraIntrinsics
    rms_px: float
    view_rms_px: Tuple[float, ...]
    rvecs: Tuple[Tuple[float, float, float], ...]
    tvecs: Tuple[Tuple[float, float, float], ...]


def board_points(cols: int, rows: int, square_m: float) -> np.ndarray:
    """Inner corners on the board plane, (cols·rows, 3) float32, in OpenCV's order (row by row)."""
    gx, gy = np.meshgrid(np.arange(cols), np.arange(rows))
    return (np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)]) * square_m).astype(np.float32)


def find_corners(gray: np.ndarray, cols: int, rows: int) -> Optional[np.ndarray]:
    """Sub-pixel inner corners of a ``cols × rows`` chessboard, (cols·rows, 2) float32, or None.

    Parameters
    ----------
    gray : (H, W) uint8 array
    cols, rows : int
        Inner corners along the board's long and short side (``9x6`` for a 10×7-square board).
    """
    flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
    ok, corners = cv2.findChessboardCorners(gray, (cols, rows), flags=flags)
    if not ok:
        return None
    # the search window: a third of the smallest square side seen, at least 2 px
    c = corners.reshape(rows, cols, 2)
    side = min(np.linalg.norm(np.diff(c, axis=0), axis=2).min(), np.linalg.norm(np.diff(c, axis=1), axis=2).min())
    win = int(max(2, min(11, side / 3)))
    corners = cv2.cornerSubPix(gray, corners, (win, win), (-1, -1), SUBPIX)
    return corners.reshape(-1, 2)


def _tilt(corners: np.ndarray, obj: np.ndarray, size: Tuple[int, int]) -> Tuple[float, float]:
    """(tilt from face-on in degrees, azimuth of the tilt axis in degrees 0–180) with a rough camera."""
    w, h = size
    k = np.array([[w, 0, (w - 1) / 2], [0, w, (h - 1) / 2], [0, 0, 1.0]])  # f ≈ width: a guess is enough here
    hom, _ = cv2.findHomography(obj[:, :2], corners)
    m = np.linalg.inv(k) @ hom
    r1, r2 = m[:, 0] / np.linalg.norm(m[:, 0]), m[:, 1] / np.linalg.norm(m[:, 1])
    n = np.cross(r1, r2)
    n /= np.linalg.norm(n)
    tilt = math.degrees(math.acos(min(1.0, abs(n[2]))))
    return tilt, math.degrees(math.atan2(n[1], n[0])) % 180.0


def coverage_problems(
    views: Sequence[np.ndarray], obj: Union[np.ndarray, Sequence[np.ndarray]], size: Tuple[int, int]
) -> List[str]:
    """Reasons the views cannot pin the intrinsics down; empty when they can.

    Parameters
    ----------
    views : sequence of (N, 2) arrays
        Corners found in each view.
    obj : (N, 3) array, or one (N_i, 3) array per view
        The board's corners (:func:`board_points`), or each view's own (ChArUco views are partial).
    size : (width, height)
        Frame size in pixels.
    """
    w, h = size
    problems = []
    if len(views) < MIN_VIEWS:
        problems.append(f"too few views: the board was found in {len(views)}, at least {MIN_VIEWS} are needed")
    if not views:
        return problems
    pts = np.concatenate(views)
    cells = set(zip(np.clip(pts[:, 0] * 4 // w, 0, 3).astype(int), np.clip(pts[:, 1] * 4 // h, 0, 3).astype(int)))
    if len(cells) < MIN_CELLS_FRAC * 16:
        empty = sorted({(i, j) for i in range(4) for j in range(4)} - cells)
        names = ", ".join(sorted({f"{'top' if j < 2 else 'bottom'}-{'left' if i < 2 else 'right'}" for i, j in empty}))
        problems.append(
            f"corners not spread over the image: {len(cells)} of 16 cells of a 4×4 grid hold a corner "
            f"(need {math.ceil(MIN_CELLS_FRAC * 16)}); show the board near the frame's edges and corners "
            f"(nothing in the {names} part)"
        )
    objs = [obj] * len(views) if isinstance(obj, np.ndarray) else list(obj)
    tilts = [_tilt(v, o, size) for v, o in zip(views, objs)]
    tilted = [(t, az) for t, az in tilts if t >= MIN_TILT_DEG]
    axes = {int(az // 45) for _t, az in tilted}
    if len(tilted) < MIN_TILTED_VIEWS or len(axes) < 2:
        problems.append(
            f"no tilt variety: {len(tilted)} view(s) tilted by {MIN_TILT_DEG:.0f}° or more about "
            f"{len(axes)} direction(s); need {MIN_TILTED_VIEWS} views tilted both left/right and up/down"
        )
    return problems


def fit_intrinsics(
    views: Sequence[np.ndarray],
    cols: int,
    rows: int,
    square_m: float,
    size: Tuple[int, int],
    k3: bool = False,
) -> IntrinsicsFit:
    """Fit ``fx, fy, cx, cy`` and OpenCV distortion ``(k1, k2, p1, p2, k3)`` to chessboard corners.

    Parameters
    ----------
    views : sequence of (cols·rows, 2) arrays
        Sub-pixel corners per view (:func:`find_corners`).
    cols, rows : int
    square_m : float
        Side of one square, metres (it scales the poses only, not the intrinsics).
    size : (width, height)
    k3 : bool
        Also fit the sixth-order radial term (wide lenses); otherwise it stays 0.

    Raises
    ------
    CalibrationError
        The views fail :func:`coverage_problems` (every reason is given), or the fit diverges.
    """
    obj = board_points(cols, rows, square_m)
    return fit_views(views, [obj] * len(views), size, k3)


def fit_views(
    views: Sequence[np.ndarray], objs: Sequence[np.ndarray], size: Tuple[int, int], k3: bool = False
) -> IntrinsicsFit:
    """:func:`fit_intrinsics` for views that each see their own subset of a planar target (ChArUco).

    ``views[i]`` (N_i, 2) pixels are the images of ``objs[i]`` (N_i, 3) target points (z = 0).
    """
    problems = coverage_problems(views, objs, size)
    if problems:
        raise CalibrationError("poor coverage, no fit made:\n  - " + "\n  - ".join(problems))
    flags = 0 if k3 else cv2.CALIB_FIX_K3
    img = [np.asarray(v, np.float32).reshape(-1, 1, 2) for v in views]
    obj3 = [np.asarray(o, np.float32).reshape(-1, 1, 3) for o in objs]
    rms, k, dist, rvecs, tvecs = cv2.calibrateCamera(obj3, img, size, None, None, flags=flags)
    if not (np.all(np.isfinite(k)) and k[0, 0] > 0 and k[1, 1] > 0):
        raise CalibrationError("the fit diverged: check the --board size (inner corners, e.g. 9x6)")
    per_view = []
    for v, o, rv, tv in zip(img, obj3, rvecs, tvecs):
        proj, _ = cv2.projectPoints(o, rv, tv, k, dist)
        per_view.append(float(np.sqrt(np.mean(np.sum((proj - v) ** 2, axis=2)))))
    d = tuple(float(c) for c in np.ravel(dist)[:5])
    cam = CameraIntrinsics(
        width_px=size[0], height_px=size[1],
        fx_px=float(k[0, 0]), fy_px=float(k[1, 1]), cx_px=float(k[0, 2]), cy_px=float(k[1, 2]),
        distortion=d,
    )
    return IntrinsicsFit(
        cam, float(rms), tuple(per_view),
        tuple(tuple(float(x) for x in np.ravel(r)) for r in rvecs),  # type: ignore[misc]
        tuple(tuple(float(x) for x in np.ravel(t)) for t in tvecs),  # type: ignore[misc]
    )
