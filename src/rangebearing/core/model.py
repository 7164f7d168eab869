"""Range and bearing from the two band centroids: the paper's model and a pinhole model.

Paper (Balanji & Turgut), equations 1–5, in the pixels of the calibration resolution::

    d_v = k / L            (k = 3500 px·cm = 35 px·m for d_v in 28–72 cm)
    d_h = k_h · px         (px: horizontal pixel offset from the image centre)
    θ   = atan(d_h / d_v)
    d   = d_v / cos θ

Pinhole (the default). With the optical axis horizontal, a vertical segment of
height H at depth Z images to L = f·H/Z pixels wherever it is in the frame, and
the horizontal angle to a point is atan(x/f) after undistortion, independent
of range. The band centroids lie on the cylinder's *near* surface, about
c ≈ (π/4)·radius closer along the line of sight than the axis, so::

    θ = atan(−x_n)              (x_n undistorted normalised column; + is left)
    d = S / (L_n·cos θ) + c     (range to the axis; L_n = L/f, S = band spacing 0.055 m)
    d_v = d·cos θ,  d_h = d·sin θ
"""

from __future__ import annotations

import math
from typing import Tuple

import cv2
import numpy as np

from .params import ModelParams
from .types import XY, CameraIntrinsics, LandmarkGeometry


def normalised(points_px: np.ndarray, cam: CameraIntrinsics) -> np.ndarray:
    """Pixel coordinates (N, 2) → undistorted normalised coordinates (N, 2).

    Without distortion coefficients this is ``((x − cx)/fx, (y − cy)/fy)``.
    """
    pts = np.asarray(points_px, dtype=np.float64).reshape(-1, 2)
    if not cam.has_distortion:
        return (pts - (cam.cx_px, cam.cy_px)) / (cam.fx_px, cam.fy_px)
    k = np.array([[cam.fx_px, 0.0, cam.cx_px], [0.0, cam.fy_px, cam.cy_px], [0.0, 0.0, 1.0]])
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 40, 1e-10)
    src, dist = pts.reshape(-1, 1, 2), np.asarray(cam.distortion, np.float64)
    if hasattr(cv2, "undistortPointsIter"):  # OpenCV 4.x
        out = cv2.undistortPointsIter(src, k, dist, None, None, crit)
    else:  # OpenCV 5 folded the criteria into undistortPoints
        out = cv2.undistortPoints(src, k, dist, None, None, None, crit)
    return out.reshape(-1, 2)


def axis_bearing(bearing_c_rad: float, range_m: float, radius_m: float) -> float:
    """Bearing of the cylinder's axis from the bearing of its visible centroid.

    The visible outline spans the tangent rays at θ ± α, α = asin(r/d); its
    image centre is the mean of their tangents, which sits slightly off the
    axis for θ ≠ 0. Solving ``(tan(θ−α) + tan(θ+α))/2 = tan θ_c`` for θ gives
    ``2θ = φ + asin(m·cos 2α / √(1+m²))`` with ``m = tan θ_c``, ``φ = atan m``.
    """
    if range_m <= radius_m:
        return bearing_c_rad
    alpha = math.asin(radius_m / range_m)
    m = math.tan(bearing_c_rad)
    phi = math.atan(m)
    return 0.5 * (phi + math.asin(max(-1.0, min(1.0, m * math.cos(2 * alpha) / math.hypot(1.0, m)))))


def pinhole_reading(
    red_xy: XY, blue_xy: XY, cam: CameraIntrinsics, model: ModelParams, geometry: LandmarkGeometry
) -> Tuple[float, float, float, float, float]:
    """``(range_m, bearing_rad, d_v_m, d_h_m, l_px)`` from band centroids with the pinhole model."""
    if cam.has_distortion:
        (xr, yr), (xb, yb) = normalised(np.array([red_xy, blue_xy]), cam)
    else:  # the common case, without numpy: this runs for every landmark of every frame
        xr, yr = (red_xy[0] - cam.cx_px) / cam.fx_px, (red_xy[1] - cam.cy_px) / cam.fy_px
        xb, yb = (blue_xy[0] - cam.cx_px) / cam.fx_px, (blue_xy[1] - cam.cy_px) / cam.fy_px
    l_n = math.hypot(xb - xr, yb - yr)
    l_px = l_n * cam.fy_px
    bearing = math.atan(-0.5 * (xr + xb))
    rng = model.spacing_m / (l_n * math.cos(bearing)) + model.c_m
    if model.cylinder_correction:
        bearing = axis_bearing(bearing, rng, geometry.radius_m)
    return rng, bearing, rng * math.cos(bearing), rng * math.sin(bearing), l_px


def paper_reading(
    red_xy: XY, blue_xy: XY, cam: CameraIntrinsics, model: ModelParams
) -> Tuple[float, float, float, float, float]:
    """``(range_m, bearing_rad, d_v_m, d_h_m, l_px)`` with the paper's equations 1–4 as published."""
    l_px = math.hypot(blue_xy[0] - red_xy[0], blue_xy[1] - red_xy[1])
    d_v = model.k_px_m / l_px
    px = cam.cx_px - 0.5 * (red_xy[0] + blue_xy[0])  # positive left of centre
    d_h = model.kh_m_per_px * px
    theta = math.atan(d_h / d_v)
    return d_v / math.cos(theta), theta, d_v, d_h, l_px


def view_edges_rad(cam: CameraIntrinsics) -> Tuple[float, float]:
    """Bearings (radians, positive left) of the frame's right and left edges on its centre row."""
    (xl, _), (xr, _) = normalised(np.array([[-0.5, cam.cy_px], [cam.width_px - 0.5, cam.cy_px]]), cam)
    return math.atan(-xr), math.atan(-xl)


def reading(
    red_xy: XY, blue_xy: XY, cam: CameraIntrinsics, model: ModelParams, geometry: LandmarkGeometry
) -> Tuple[float, float, float, float, float]:
    """Dispatch on ``model.kind``: ``(range_m, bearing_rad, d_v_m, d_h_m, l_px)``."""
    if model.kind == "paper":
        return paper_reading(red_xy, blue_xy, cam, model)
    return pinhole_reading(red_xy, blue_xy, cam, model, geometry)


def in_envelope(range_m: float, bearing_rad: float, model: ModelParams) -> bool:
    """Whether a reading lies inside the range and bearing the model was fitted over."""
    r0, r1 = model.envelope_range_m
    b0, b1 = model.envelope_bearing_rad
    return r0 <= range_m <= r1 and b0 <= bearing_rad <= b1
