"""The band spacing seen over part of a cylinder's width: its edges are arcs, nearer at the middle.

A band edge is a horizontal circle on the cylinder; a point of it at depth ``Z`` images at the
row ``f·Y/Z``, so the band spacing seen in an image column scales as ``1/Z`` of the surface point
in that column: largest where the surface is nearest (the middle of the outline), smallest at
the limbs, where the surface turns away (``Z`` larger by up to ``r·(1 − r/d)``: 7 % at 0.2 m,
1 % at 1.5 m). The rows of a landmark seen whole are read over the middle two thirds of its
outline (:mod:`.measure`), which the calibration takes in; a landmark cut on a side (a nearer
one in front, the frame's edge) is read over the columns that show, towards one limb, where
the spacing is shorter: its range would read long. :func:`arc_scale` is the factor that takes
the spacing over the columns read to the spacing over the whole landmark's middle two thirds.
"""

from __future__ import annotations

import functools
import math
from typing import Tuple

import numpy as np

from .types import LandmarkGeometry

ARC_SAMPLES = 129  # points along the visible half of the circle
WINDOW_SAMPLES = 33  # columns sampled in a window (the profile is smooth)
MIDDLE = 1.0 / 3.0  # a whole landmark's rows are read over its outline centre ± this share of its width


@functools.lru_cache(maxsize=64)
def _arc(phi_rad: float, d_m: float, r_m: float) -> Tuple[np.ndarray, np.ndarray]:
    """``(u, w)``: normalised image column ``X/Z`` (increasing) and ``1/Z`` along the visible front of a
    circle of radius ``r_m`` whose centre lies ``d_m`` away at ``phi_rad`` right of the optical axis."""
    xc, zc = d_m * math.sin(phi_rad), d_m * math.cos(phi_rad)
    g = math.acos(min(1.0, r_m / d_m))  # the tangent rays: the visible arc is |angle from the near point| < g
    beta = np.linspace(-g, g, ARC_SAMPLES) + phi_rad
    x, z = xc + r_m * np.sin(beta), zc - r_m * np.cos(beta)
    return x / z, 1.0 / z


def arc_scale(cols_px: Tuple[float, float], axis_px: float, cx_px: float, f_px: float, white_px: float,
              geometry: LandmarkGeometry) -> float:
    """Factor (≥ about 1) taking a band spacing read over image columns ``cols_px = (a, b)`` to the one the
    whole landmark's middle two thirds would show.

    Parameters
    ----------
    cols_px : (float, float)
        First and last image column the rows were read over (full-resolution pixels).
    axis_px : float
        The landmark's outline centre (its column estimate).
    cx_px, f_px : float
        Principal point column and focal length (pixels).
    white_px : float
        The white body's height as read: the range, from the near surface, to a few per cent.
    geometry : LandmarkGeometry

    Returns
    -------
    float
        ``mean(1/Z)`` over the middle window / ``mean(1/Z)`` over ``cols_px``; 1.0 when the columns
        miss the outline. Mirror images give the same factor; a window equal to the middle one, 1.
    """
    r = geometry.radius_m
    white_m = geometry.height_m - 2 * geometry.band_height_m
    phi = math.atan((axis_px - cx_px) / f_px)
    # the white height gives the near surface's depth along the optical axis, (d - r)·cos φ
    d = f_px * white_m / max(white_px, 1e-3) / max(math.cos(phi), 1e-3) + r
    u, w = _arc(round(phi, 4), round(d, 4), r)
    lo_u, hi_u = float(u[0]), float(u[-1])
    centre, width = 0.5 * (lo_u + hi_u), hi_u - lo_u

    def mean(lo: float, hi: float) -> float:
        lo, hi = max(lo, lo_u), min(hi, hi_u)
        if not hi > lo:
            return math.nan
        return float(np.interp(np.linspace(lo, hi, WINDOW_SAMPLES), u, w).mean())

    used = mean((cols_px[0] - cx_px) / f_px, (cols_px[1] - cx_px) / f_px)
    ref = mean(centre - MIDDLE * width, centre + MIDDLE * width)
    k = ref / used
    return k if math.isfinite(k) else 1.0
