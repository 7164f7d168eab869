"""Chessboard frames with known intrinsics, distortion and poses (for testing ``intrinsics``).

A planar board of ``cols × rows`` inner corners (``cols+1 × rows+1`` squares,
one square of white margin around) is seen under a pose ``(rvec, tvec)``
(OpenCV convention: board point ``X`` is at ``R·X + t`` in the camera frame,
x right, y down, z forward). Each pixel is the mean of ``s × s`` sub-pixel
samples: every sample's ray is undistorted exactly (OpenCV's model inverted,
:func:`.camera._undistort`), intersected with the board plane through the
homography ``[r1 r2 t]``, and coloured by the square it lands in.
"""

from __future__ import annotations

import functools
import math
from typing import List, NamedTuple, Optional, Tuple

import cv2
import numpy as np

from ..core.intrinsics import board_points
from ..core.types import CameraIntrinsics
from .camera import _coefficients, _undistort

BLACK, WHITE, BACKGROUND = 25.0, 230.0, 120.0


class BoardView(NamedTuple):
    """One rendered view: the BGR frame, its pose and the true corner pixels (N, 2)."""

    image: np.ndarray
    rvec: np.ndarray
    tvec: np.ndarray
    corners_px: np.ndarray


def camera_matrix(cam: CameraIntrinsics) -> np.ndarray:
    return np.array([[cam.fx_px, 0.0, cam.cx_px], [0.0, cam.fy_px, cam.cy_px], [0.0, 0.0, 1.0]])


@functools.lru_cache(maxsize=4)
def _sample_rays(cam: CameraIntrinsics, s: int) -> Tuple[np.ndarray, np.ndarray]:
    """Undistorted rays of every sub-pixel sample, (H·s, W·s) each.

    Exact (Newton-polished) at the pixel centres of a grid one pixel wider on
    every side, bilinear between them: the undistortion map is smooth, so the
    interpolation error is far below a thousandth of a pixel.
    """
    off = (np.arange(s) + 0.5) / s - 0.5
    gu, gv = np.arange(-1, cam.width_px + 1, dtype=np.float64), np.arange(-1, cam.height_px + 1, dtype=np.float64)
    uu, vv = np.meshgrid(gu, gv)
    xd, yd = (uu - cam.cx_px) / cam.fx_px, (vv - cam.cy_px) / cam.fy_px
    if not cam.has_distortion:
        u = (np.arange(cam.width_px)[:, None] + off[None, :]).ravel()
        v = (np.arange(cam.height_px)[:, None] + off[None, :]).ravel()
        return tuple(np.meshgrid((u - cam.cx_px) / cam.fx_px, (v - cam.cy_px) / cam.fy_px))  # type: ignore[return-value]
    gx, gy = _undistort(xd, yd, cam, _coefficients(cam))

    def weights(n: int) -> Tuple[np.ndarray, np.ndarray]:
        at = (np.arange(n)[:, None] + off[None, :]).ravel() + 1.0  # in grid indices
        i = np.minimum(np.floor(at).astype(np.int64), n)  # the grid has n + 2 points
        return i, at - i

    iu, fu = weights(cam.width_px)
    iv, fv = weights(cam.height_px)
    out = []
    for g in (gx, gy):
        top = g[iv][:, iu] * (1 - fu) + g[iv][:, iu + 1] * fu
        bottom = g[iv + 1][:, iu] * (1 - fu) + g[iv + 1][:, iu + 1] * fu
        out.append(top * (1 - fv)[:, None] + bottom * fv[:, None])
    return out[0], out[1]


def render_board(
    cam: CameraIntrinsics, cols: int, rows: int, square_m: float, rvec: np.ndarray, tvec: np.ndarray, s: int = 3
) -> np.ndarray:
    """The board under one pose, (H, W, 3) uint8 BGR, anti-aliased by ``s × s`` supersampling."""
    box = _board_box(cam, cols, rows, square_m, rvec, tvec)
    grey = np.full((cam.height_px, cam.width_px), BACKGROUND)
    if box is None:
        return np.repeat(np.clip(grey + 0.5, 0, 255).astype(np.uint8)[:, :, None], 3, axis=2)
    r0, r1, c0, c1 = box  # only the pixels the board can cover are sampled
    px, py, facing = plane_coords(cam, box, rvec, tvec, s)
    with np.errstate(invalid="ignore"):
        bu, bv = px / square_m + 1.0, py / square_m + 1.0  # in squares, 0 at the board's edge
        on_board = facing & (bu >= -1) & (bu < cols + 2) & (bv >= -1) & (bv < rows + 2)
        in_grid = (bu >= 0) & (bu < cols + 1) & (bv >= 0) & (bv < rows + 1)
        dark = ((np.floor(bu) + np.floor(bv)) % 2 == 0) & in_grid
    patch = np.where(on_board, np.where(dark, BLACK, WHITE), BACKGROUND)
    grey[r0:r1, c0:c1] = patch.reshape(r1 - r0, s, c1 - c0, s).mean(axis=(1, 3))
    return np.repeat(np.clip(grey + 0.5, 0, 255).astype(np.uint8)[:, :, None], 3, axis=2)


def _board_box(
    cam: CameraIntrinsics, cols: int, rows: int, square_m: float, rvec: np.ndarray, tvec: np.ndarray
) -> Optional[Tuple[int, int, int, int]]:
    """Pixel rows and columns ``(r0, r1, c0, c1)`` holding the whole board with its margin, or None if behind."""
    return plane_box(cam, (-2 * square_m, -2 * square_m, (cols + 1) * square_m, (rows + 1) * square_m), rvec, tvec)


def plane_box(
    cam: CameraIntrinsics, rect_m: Tuple[float, float, float, float], rvec: np.ndarray, tvec: np.ndarray
) -> Optional[Tuple[int, int, int, int]]:
    """Pixel rows and columns ``(r0, r1, c0, c1)`` that the plane rectangle ``(x0, y0, x1, y1)`` can cover."""
    t = np.linspace(0.0, 1.0, 25)
    x0, y0, x1, y1 = rect_m
    xs = np.concatenate([x0 + (x1 - x0) * t, np.full_like(t, x1), x1 - (x1 - x0) * t, np.full_like(t, x0)])
    ys = np.concatenate([np.full_like(t, y0), y0 + (y1 - y0) * t, np.full_like(t, y1), y1 - (y1 - y0) * t])
    edge = np.column_stack([xs, ys, np.zeros_like(xs)])
    r, _ = cv2.Rodrigues(np.asarray(rvec, np.float64))
    z = (edge @ r.T + np.ravel(tvec))[:, 2]
    if np.any(z <= 1e-6):
        return None if np.all(z <= 1e-6) else (0, cam.height_px, 0, cam.width_px)
    uv, _ = cv2.projectPoints(edge, rvec, tvec, camera_matrix(cam), np.asarray(cam.distortion, np.float64))
    uv = uv.reshape(-1, 2)
    c0, c1 = int(max(0, np.floor(uv[:, 0].min()) - 4)), int(min(cam.width_px, np.ceil(uv[:, 0].max()) + 5))
    r0, r1 = int(max(0, np.floor(uv[:, 1].min()) - 4)), int(min(cam.height_px, np.ceil(uv[:, 1].max()) + 5))
    return (r0, r1, c0, c1) if r0 < r1 and c0 < c1 else None


def plane_coords(
    cam: CameraIntrinsics, box: Tuple[int, int, int, int], rvec: np.ndarray, tvec: np.ndarray, s: int
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Plane coordinates ``(X, Y)`` (m) of every sub-pixel sample in ``box``, and where the plane faces the camera."""
    r0, r1, c0, c1 = box
    x, y = (a[r0 * s : r1 * s, c0 * s : c1 * s] for a in _sample_rays(cam, s))
    r, _ = cv2.Rodrigues(np.asarray(rvec, np.float64))
    a = np.linalg.inv(np.column_stack([r[:, 0], r[:, 1], np.asarray(tvec, np.float64).ravel()]))
    with np.errstate(divide="ignore", invalid="ignore"):
        w = a[2, 0] * x + a[2, 1] * y + a[2, 2]
        return (a[0, 0] * x + a[0, 1] * y + a[0, 2]) / w, (a[1, 0] * x + a[1, 1] * y + a[1, 2]) / w, w > 0


def random_pose(
    rng: np.random.Generator, cam: CameraIntrinsics, width_m: float, centre_m: np.ndarray, max_tilt_deg: float
) -> Tuple[np.ndarray, np.ndarray]:
    """``(rvec, tvec)``: a target ``width_m`` wide filling 25–55 % of the frame width, tilted up to
    ``max_tilt_deg`` about a random axis, its centre on the ray of a random pixel."""
    tilt = math.radians(rng.uniform(5.0, max_tilt_deg))
    axis_ang = rng.uniform(0, 2 * math.pi)
    axis = np.array([math.cos(axis_ang), math.sin(axis_ang), 0.0])
    spin = cv2.Rodrigues(np.array([0.0, 0.0, rng.uniform(-0.3, 0.3)]))[0]
    r = cv2.Rodrigues(axis * tilt)[0] @ spin
    z = cam.fx_px * width_m / (rng.uniform(0.25, 0.55) * cam.width_px)
    target = np.array([rng.uniform(0.1, 0.9) * cam.width_px, rng.uniform(0.1, 0.9) * cam.height_px])
    ray = np.array([(target[0] - cam.cx_px) / cam.fx_px, (target[1] - cam.cy_px) / cam.fy_px, 1.0])
    return cv2.Rodrigues(r)[0].ravel(), ray * z - r @ centre_m


def project_corners(
    cam: CameraIntrinsics, cols: int, rows: int, square_m: float, rvec: np.ndarray, tvec: np.ndarray
) -> np.ndarray:
    """True pixel positions of the inner corners, (N, 2), distortion applied."""
    obj = board_points(cols, rows, square_m).astype(np.float64)
    pts, _ = cv2.projectPoints(obj, rvec, tvec, camera_matrix(cam), np.asarray(cam.distortion, np.float64))
    return pts.reshape(-1, 2)


def random_views(
    cam: CameraIntrinsics, cols: int, rows: int, square_m: float, n: int, seed: int = 0, max_tilt_deg: float = 35.0
) -> List[BoardView]:
    """``n`` views of the board, tilted up to ``max_tilt_deg`` about random axes and spread over the frame.

    Each view's board fills roughly 25–55 % of the frame width, and every
    corner lies at least 12 px inside the frame.
    """
    rng = np.random.default_rng(seed)
    centre = np.array([(cols - 1) * square_m / 2, (rows - 1) * square_m / 2, 0.0])
    views: List[BoardView] = []
    while len(views) < n:
        rvec, t = random_pose(rng, cam, (cols + 1) * square_m, centre, max_tilt_deg)
        corners = project_corners(cam, cols, rows, square_m, rvec, t)
        m = 12.0
        if not (np.all(corners >= m) and np.all(corners[:, 0] <= cam.width_px - 1 - m)
                and np.all(corners[:, 1] <= cam.height_px - 1 - m)):
            continue
        views.append(BoardView(render_board(cam, cols, rows, square_m, rvec, t), rvec, t, corners))
    return views
