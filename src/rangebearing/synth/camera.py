"""The synthetic camera: per-pixel undistorted rays, forward projection, image extents.

Pixel centres sit at integer coordinates, origin at the top-left pixel centre.
Normalised coordinates follow OpenCV (x right, y DOWN, z forward); the world
frame of :mod:`.scene` has Y up, so a world direction is ``(x, -y, 1)``.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple, Optional, Sequence, Tuple

import cv2
import numpy as np

from ..core.types import CameraIntrinsics
from ..errors import SceneError
from .scene import LandmarkPose, Scene

Rect = Tuple[int, int, int, int]  # row0, row1, col0, col1 (half-open)
BoxPx = Tuple[float, float, float, float]  # u0, v0, u1, v1 (pixel centres)


class RayGrid(NamedTuple):
    """Undistorted normalised ray of every pixel centre and its derivative.

    ``x``, ``y``: (H, W) float64, NaN where the distortion model has no inverse.
    ``jxx = dx/du``, ``jxy = dx/dv``, ``jyx = dy/du``, ``jyy = dy/dv`` (H, W),
    so a sub-pixel offset ``(du, dv)`` has the ray ``x + jxx·du + jxy·dv`` and
    likewise for ``y`` (exact without distortion, error < 1e-3 px with it).
    """

    x: np.ndarray
    y: np.ndarray
    jxx: np.ndarray
    jxy: np.ndarray
    jyx: np.ndarray
    jyy: np.ndarray


def _coefficients(camera: CameraIntrinsics) -> np.ndarray:
    d = tuple(camera.distortion)
    if len(d) not in (0, 4, 5, 8):
        raise SceneError(
            [f"camera.distortion: {len(d)} coefficients; the renderer supports 4, 5 or 8"], "synthetic camera"
        )
    return np.array(d + (0.0,) * (8 - len(d)), dtype=np.float64)


def distort(x: np.ndarray, y: np.ndarray, k: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """OpenCV's distortion model on normalised coordinates.

    ``k`` is ``(k1, k2, p1, p2, k3, k4, k5, k6)``; returns distorted ``(x, y)``.
    """
    k1, k2, p1, p2, k3, k4, k5, k6 = (float(c) for c in k)
    r2 = x * x + y * y
    radial = (1 + r2 * (k1 + r2 * (k2 + r2 * k3))) / (1 + r2 * (k4 + r2 * (k5 + r2 * k6)))
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    return xd, yd


def _forward_jacobian(x: np.ndarray, y: np.ndarray, k: np.ndarray) -> Tuple[np.ndarray, ...]:
    h = 1e-7
    xa, ya = distort(x + h, y, k)
    xb, yb = distort(x - h, y, k)
    xc, yc = distort(x, y + h, k)
    xe, ye = distort(x, y - h, k)
    return (xa - xb) / (2 * h), (xc - xe) / (2 * h), (ya - yb) / (2 * h), (yc - ye) / (2 * h)


def _undistort(
    xd: np.ndarray, yd: np.ndarray, camera: CameraIntrinsics, k: np.ndarray
) -> Tuple[np.ndarray, np.ndarray]:
    """Exact inverse of :func:`distort`: OpenCV's estimate polished by Newton steps."""
    cam = np.array([[camera.fx_px, 0, camera.cx_px], [0, camera.fy_px, camera.cy_px], [0, 0, 1]])
    pix = np.stack([xd * camera.fx_px + camera.cx_px, yd * camera.fy_px + camera.cy_px], -1)
    first = cv2.undistortPoints(pix.reshape(-1, 1, 2), cam, k).reshape((*xd.shape, 2))
    x, y = first[..., 0].copy(), first[..., 1].copy()
    for _ in range(30):
        fx, fy = distort(x, y, k)
        ex, ey = fx - xd, fy - yd
        if np.nanmax(np.abs(ex) + np.abs(ey), initial=0.0) < 1e-14:
            break
        a, b, c, d = _forward_jacobian(x, y, k)
        det = a * d - b * c
        with np.errstate(divide="ignore", invalid="ignore"):
            x = x - (d * ex - b * ey) / det
            y = y - (a * ey - c * ex) / det
    fx, fy = distort(x, y, k)
    a, b, c, d = _forward_jacobian(x, y, k)
    bad = ~(np.abs(fx - xd) + np.abs(fy - yd) < 1e-9) | ~(a * d - b * c > 0)
    x[bad] = np.nan
    y[bad] = np.nan
    return x, y


@functools.lru_cache(maxsize=8)
def ray_grid(camera: CameraIntrinsics) -> RayGrid:
    """The (cached, read-only) :class:`RayGrid` of a camera."""
    h, w = camera.height_px, camera.width_px
    u, v = np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64))
    xd = (u - camera.cx_px) / camera.fx_px
    yd = (v - camera.cy_px) / camera.fy_px
    k = _coefficients(camera)
    if not camera.has_distortion:
        zero = np.zeros((h, w))
        grid = RayGrid(xd, yd, zero + 1.0 / camera.fx_px, zero, zero, zero + 1.0 / camera.fy_px)
    else:
        x, y = _undistort(xd, yd, camera, k)
        a, b, c, d = _forward_jacobian(x, y, k)
        det = a * d - b * c
        # d(undistorted)/d(pixel) = inverse forward Jacobian · diag(1/fx, 1/fy)
        grid = RayGrid(
            x, y, d / det / camera.fx_px, -b / det / camera.fy_px, -c / det / camera.fx_px, a / det / camera.fy_px
        )
    for arr in grid:
        arr.setflags(write=False)
    return grid


def project(
    camera: CameraIntrinsics, camera_height_m: float, x_m: np.ndarray, y_m: np.ndarray, z_m: np.ndarray
) -> Tuple[np.ndarray, np.ndarray]:
    """World points to pixel coordinates ``(u, v)``, with distortion; NaN behind the camera."""
    x_m, y_m, z_m = (np.asarray(a, dtype=np.float64) for a in (x_m, y_m, z_m))
    with np.errstate(divide="ignore", invalid="ignore"):
        zs = np.where(z_m > 1e-9, z_m, np.nan)
        xn, yn = x_m / zs, (camera_height_m - y_m) / zs
    if camera.has_distortion:
        xn, yn = distort(xn, yn, _coefficients(camera))
    return camera.cx_px + camera.fx_px * xn, camera.cy_px + camera.fy_px * yn


def pixel_rect(
    camera: CameraIntrinsics, xn: Sequence[float], yn: Sequence[float], pad_px: float = 2.0
) -> Optional[Rect]:
    """Pixels whose ray falls inside the normalised box ``xn × yn`` (padded), or None."""
    h, w = camera.height_px, camera.width_px
    if not camera.has_distortion:
        c0 = math.floor(camera.cx_px + camera.fx_px * xn[0] - pad_px)
        c1 = math.ceil(camera.cx_px + camera.fx_px * xn[1] + pad_px) + 1
        r0 = math.floor(camera.cy_px + camera.fy_px * yn[0] - pad_px)
        r1 = math.ceil(camera.cy_px + camera.fy_px * yn[1] + pad_px) + 1
    else:
        g = ray_grid(camera)
        px, py = pad_px / camera.fx_px, pad_px / camera.fy_px
        m = (g.x >= xn[0] - px) & (g.x <= xn[1] + px) & (g.y >= yn[0] - py) & (g.y <= yn[1] + py)
        rows, cols = np.flatnonzero(m.any(axis=1)), np.flatnonzero(m.any(axis=0))
        if rows.size == 0:
            return None
        r0, r1, c0, c1 = int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1
    r0, r1, c0, c1 = max(r0, 0), min(r1, h), max(c0, 0), min(c1, w)
    return (r0, r1, c0, c1) if r0 < r1 and c0 < c1 else None


def cylinder_bbox_px(
    scene: Scene, x_m: float, z_m: float, radius_m: float, bottom_m: float, top_m: float
) -> Optional[BoxPx]:
    """Image extent ``(u0, v0, u1, v1)`` of a vertical cylinder, unclipped; None if behind."""
    ang = np.linspace(0.0, 2.0 * np.pi, 360, endpoint=False)
    heights = np.linspace(bottom_m, top_m, 7)
    xs = (x_m + radius_m * np.cos(ang))[None, :] + 0.0 * heights[:, None]
    zs = (z_m + radius_m * np.sin(ang))[None, :] + 0.0 * heights[:, None]
    ys = heights[:, None] + 0.0 * ang[None, :]
    return points_bbox(scene, xs, ys, zs)


def points_bbox(scene: Scene, xs: np.ndarray, ys: np.ndarray, zs: np.ndarray) -> Optional[BoxPx]:
    """Image extent ``(u0, v0, u1, v1)`` of world points, unclipped; None if any is behind the camera."""
    if np.min(zs) <= 1e-3:
        return None
    u, v = project(scene.camera, scene.camera_height_m, xs, ys, zs)
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(v))):
        return None
    return float(u.min()), float(v.min()), float(u.max()), float(v.max())


def landmark_bbox_px(scene: Scene, lm: LandmarkPose, with_robot: bool = False) -> Optional[BoxPx]:
    """Image extent of a landmark's cylinder (and of its robot, if asked)."""
    g = scene.geometry
    box = cylinder_bbox_px(scene, lm.x_m, lm.z_m, g.radius_m, lm.base_height_m, lm.base_height_m + g.height_m)
    if box is None or not with_robot:
        return box
    body = cylinder_bbox_px(scene, lm.x_m, lm.z_m, scene.robot_radius_m, 0.0, lm.base_height_m)
    if body is None:
        return None
    return min(box[0], body[0]), min(box[1], body[1]), max(box[2], body[2]), max(box[3], body[3])


def inside_image(camera: CameraIntrinsics, box: Optional[BoxPx], margin_px: float = 0.0) -> bool:
    """Whether an image extent lies wholly inside the frame, ``margin_px`` from its edges."""
    if box is None:
        return False
    u0, v0, u1, v1 = box
    return (
        u0 >= margin_px - 0.5
        and v0 >= margin_px - 0.5
        and u1 <= camera.width_px - 0.5 - margin_px
        and v1 <= camera.height_px - 0.5 - margin_px
    )
