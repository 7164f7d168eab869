"""Where a candidate's bands are, to a fraction of a pixel: rows from band edges, columns from limbs.

Rows: each band's two edges by the two-level integral of :mod:`.edges`, over
the landmark's own columns, so a neighbour beside it does not count. A band
whose outer edge merges with a same-coloured background is placed from its
inner edge and the white body's height instead.

Columns: a landmark seen whole is measured by the saturation-weighted moments
of :mod:`.refine`. One cut on a side (a nearer landmark in front, a neighbour
touching it) is placed from its other limb, half a silhouette away.
"""

from __future__ import annotations

import math
from typing import Optional, Tuple

import numpy as np

from .._compat import frozen
from .color import Gains
from .edges import band_rows, excess, limb, linear_table
from .refine import Pyramid
from .structure import Candidate
from .types import LandmarkGeometry

CENTROID_SIGMA_X_PX = 0.15  # column centroid of a whole landmark (saturation moments)
LIMB_SIGMA_X_PX = 0.8  # a limb edge on a shaded cylinder side
MAX_SAMPLES = 24  # columns (rows) averaged into a row (column) profile


@frozen
class Rows:
    """A candidate's band centres (rows, full-resolution pixels) and the white body's height."""

    red_y_px: float
    blue_y_px: float
    white_px: float
    sigma_l_px: float
    red_merged: bool
    blue_merged: bool


def _tile(bgr: np.ndarray, x0: int, y0: int, x1: int, y1: int, col_step: int = 1, row_step: int = 1):
    """The frame's region (clipped), every ``col_step``-th column and ``row_step``-th row, and its origin.

    Profiles are means along one axis, so thinning the other keeps them linear in
    coverage (an area-averaged pyramid averages *encoded* values, which does not).
    """
    h, w = bgr.shape[:2]
    x0, y0, x1, y1 = max(0, x0), max(0, y0), min(w, x1), min(h, y1)
    return bgr[y0:y1:row_step, x0:x1:col_step], x0, y0


def _step(n: int) -> int:
    """Thinning that keeps about MAX_SAMPLES of ``n`` lines."""
    return max(1, n // MAX_SAMPLES)


def measure_rows(
    bgr: np.ndarray, c: Candidate, gains: Gains, geometry: LandmarkGeometry, x_px: Optional[float] = None
) -> Optional[Rows]:
    """Band centre rows of a candidate, or ``None`` when a band shows no colour step at the white body.

    The profile is taken over the middle two thirds of the columns around ``x_px``
    (the landmark's measured centre, when it is seen whole; limbs curve and
    darken), so a full scan and a tracking window use the same columns.
    """
    white_m = geometry.height_m - 2 * geometry.band_height_m
    band_px = c.white_px * geometry.band_height_m / white_m
    f = 1
    rx, ry, rw, rh = c.red_bbox_px
    by, bh = c.blue_bbox_px[1], c.blue_bbox_px[3]
    a, b = (x_px - rw / 3, x_px + rw / 3) if x_px is not None and not (c.cut_left or c.cut_right) else (rx, rx + rw)
    cx0, cx1 = int(np.floor(a + 0.5)), int(np.ceil(b - 0.5)) + 1
    step = _step(cx1 - cx0)
    pad = int(band_px) + 6
    tile, ox, oy = _tile(bgr, cx0, ry - pad, cx1, by + bh + pad, col_step=step)
    if tile.shape[1] < 1:
        return None
    er, eb = excess(tile, gains)
    # end columns count by the share of them inside [a, b]: the profile moves smoothly with x
    cols = ox + step * np.arange(tile.shape[1])
    wgt = np.clip(np.minimum(cols + 0.5, b) - np.maximum(cols - 0.5, a), 0.0, 1.0).astype(np.float32)
    if wgt.sum() <= 0:
        return None
    wgt *= len(wgt) / wgt.sum()
    er, eb = er * wgt, eb * wgt
    hb, hw = band_px / f, c.white_px / f
    r_exp = (ry + 0.5 * rh - oy) / f - 0.5
    b_exp = (by + 0.5 * bh - oy) / f - 0.5
    red = _band(er, r_exp, hb, hw, True)
    blue = _band(eb, b_exp, hb, hw, False)
    if red is None or blue is None or not blue.inner > red.inner:
        return None
    white = blue.inner - red.inner
    k = 0.5 * geometry.band_height_m / white_m
    red_y = red.inner - k * white if red.merged else red.centre
    blue_y = blue.inner + k * white if blue.merged else blue.centre
    sigma = float(np.hypot(red.sigma, blue.sigma)) * (1.0 + (2 * k if red.merged or blue.merged else 0.0))
    return Rows(
        oy + (red_y + 0.5) * f - 0.5,
        oy + (blue_y + 0.5) * f - 0.5,
        white * f,
        sigma * f,
        red.merged,
        blue.merged,
    )


def _band(p2d: np.ndarray, expected: float, hb: float, hw: float, red: bool):
    """:func:`.edges.band_rows` around the row of strongest colour near ``expected``."""
    n = p2d.shape[0]
    lo, hi = max(0, int(expected - 0.5 * hb - 3)), min(n, int(expected + 0.5 * hb + 4))
    if hi <= lo:
        return None
    prof = p2d[lo:hi].mean(axis=1)
    top = int(np.argmax(prof))
    strong = prof >= 0.5 * prof[top]
    first, last = top, top  # the band's rows: the run of strong colour around the strongest row
    while first > 0 and strong[first - 1]:
        first -= 1
    while last < len(prof) - 1 and strong[last + 1]:
        last += 1
    mid = lo + (first + last) // 2
    half = max(0, int(0.5 * hb - 1.5))
    into_white = round(min(0.5 * hb + 4, 0.5 * hb + 0.4 * hw))  # past the blurred edge, no farther
    beyond = round(0.5 * hb + 3)
    if red:
        return band_rows(p2d, mid - half, mid + half, True, mid + into_white, mid - beyond)
    return band_rows(p2d, mid - half, mid + half, False, mid - into_white, mid + beyond)


def measure_columns(
    bgr: np.ndarray,
    c: Candidate,
    gains: Gains,
    geometry: LandmarkGeometry,
    fy_px: float,
    rows: Rows,
    pyramid: Optional[Pyramid] = None,
) -> Optional[Tuple[float, float]]:
    """``(x_px, sigma_x_px)`` of a landmark cut on exactly one side, from its other limb; else ``None``.

    The silhouette's half-width is ``white·r/white_height·(1 − r/d)``: the white
    body is measured on the near surface (depth d − r), the outline at the axis.
    """
    if c.cut_left == c.cut_right:
        return None
    white_m = geometry.height_m - 2 * geometry.band_height_m
    band_px = rows.white_px * geometry.band_height_m / white_m
    f = 1
    rx, _, rw, _ = c.red_bbox_px
    d = fy_px * white_m / max(rows.white_px, 1e-3) + geometry.radius_m
    half = rows.white_px * geometry.radius_m / white_m * (1.0 - geometry.radius_m / d)
    reach = round(2 * half) + 4
    xs = []
    for y_c, is_red in ((rows.red_y_px, True), (rows.blue_y_px, False)):
        y0, y1 = int(y_c - 0.3 * band_px), int(y_c + 0.3 * band_px) + 1
        x0, x1 = (rx - 4, rx + rw + reach) if c.cut_left else (rx - reach, rx + rw + 4)
        tile, ox, _ = _tile(bgr, x0, y0, x1, y1, row_step=_step(y1 - y0))
        er, eb = excess(tile, gains)
        lin_sum = np.maximum(linear_table()[tile].sum(axis=2), 1e-3)
        q = ((er if is_red else eb) / lin_sum).mean(axis=0)  # chromaticity: shading does not move it
        n = len(q)
        if n < 4:
            continue
        if c.cut_left:  # the right limb is natural: start inside, run right
            core = max(0, min(n - 1, int((rx + rw - ox) / f) - int(half / f)))
            end = n - 1
            level = float(np.median(q[max(0, core - 2) : core + 3]))
            edge = limb(q, core, end, level, float(q[end]))
            xs.append(ox + (edge + 0.5) * f - 0.5 - half)
        else:
            core = max(0, min(n - 1, int((rx - ox) / f) + int(half / f)))
            level = float(np.median(q[max(0, core - 2) : core + 3]))
            edge = limb(q, core, 0, level, float(q[0]))
            xs.append(ox + (edge + 0.5) * f - 0.5 + half)
    xs = [x for x in xs if math.isfinite(x)]
    x = float(np.mean(xs)) if xs else math.nan
    if not rx - half <= x <= rx + rw + half:  # no limb where the structure said: keep the moments
        return None
    return x, LIMB_SIGMA_X_PX
