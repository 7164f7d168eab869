"""Where a candidate's bands are, to a fraction of a pixel: rows from band edges, columns from limbs.

Rows: each band's two edges by the two-level integral of :mod:`.edges`, over
the landmark's own columns, so a neighbour beside it does not count. A band
whose outer edge merges with a same-coloured background, or a blue band whose
lower part a nearer robot hides, is placed from its inner edge and the white
body's height instead.

Columns: a landmark seen whole is measured by the saturation-weighted moments
of :mod:`.refine`. One cut on a side (a nearer landmark in front, a neighbour
touching it, the frame's edge) is placed from its other limb, by the tangent
rays of its outline.
"""

from __future__ import annotations

import dataclasses
import math
from typing import List, Optional, Sequence, Tuple

import numpy as np

from .._compat import frozen
from .color import Gains
from .edges import BandEdges, band_rows, excess, limb, linear_table
from .refine import Pyramid
from .structure import Candidate
from .types import LandmarkGeometry

CENTROID_SIGMA_X_PX = 0.15  # column centroid of a whole landmark (saturation moments)
LIMB_SIGMA_X_PX = 0.8  # a limb edge on a shaded cylinder side
OUTLINE_ITERATIONS = 4  # fixed-point steps for the axis angle (each gains about two decimal places)
LIMB_AGREE_PX = 1.5  # the two bands' limbs of one cylinder agree within this; farther apart, one was widened
MAX_SAMPLES = 24  # columns (rows) averaged into a row (column) profile
SHORT_BAND = 0.8  # a blue band seen shorter than this share of the red one (both 15 mm) is partly hidden
WHITE_MATCH = 0.1  # ... judged only when the white height agrees this well with the structure search's
FRAME_EDGE_PX = 2  # a run starting this close to the frame's edge (½-resolution columns) may be cut by it


@frozen
class Rows:
    """A candidate's band centres (rows, full-resolution pixels) and the white body's height.

    ``red_merged``/``blue_merged``: the band is placed from its inner edge and the
    white height, because its outer edge is not its own (merged with a background
    of its colour, or hidden). ``red_px``/``blue_px``: each band's height between
    its two measured edges (NaN when merged).
    """

    red_y_px: float
    blue_y_px: float
    white_px: float
    sigma_l_px: float
    red_merged: bool
    blue_merged: bool
    red_px: float = math.nan
    blue_px: float = math.nan


def _tile(bgr: np.ndarray, x0: int, y0: int, x1: int, y1: int, col_step: int = 1, row_step: int = 1):
    """The frame's region (clipped), every ``col_step``-th column and ``row_step``-th row, and its origin.

    Profiles are means along one axis, so thinning the other keeps them linear in
    coverage (an area-averaged pyramid averages *encoded* values, which does not).
    """
    h, w = bgr.shape[:2]
    x0, y0, x1, y1 = max(0, x0), max(0, y0), min(w, x1), min(h, y1)
    return bgr[y0:y1:row_step, x0:x1:col_step], x0, y0


def cut_sides(c: Candidate, frame_w_px: int) -> Tuple[bool, bool]:
    """``(left, right)``: sides of the candidate that are no limb of the cylinder.

    Besides what the structure search saw (a nearer landmark, a touching
    neighbour), the frame's own edge cuts a landmark: the moments of what is
    left would place it towards the inside, by up to half a silhouette.
    """
    rx, _, rw, _ = c.red_bbox_px
    return c.cut_left or rx <= FRAME_EDGE_PX, c.cut_right or rx + rw >= frame_w_px - FRAME_EDGE_PX


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
    return measure_rows_all(bgr, [c], gains, geometry, [x_px])[0]


RowWindow = Tuple[int, int, int, int, int, float, float]  # x0, y0, x1, y1, column step, then [a, b]


def _row_window(shape: Tuple[int, ...], c: Candidate, geometry: LandmarkGeometry,
                x_px: Optional[float]) -> Optional[RowWindow]:
    """The frame region (clipped) whose column profile :func:`measure_rows` reads, or ``None`` if empty."""
    white_m = geometry.height_m - 2 * geometry.band_height_m
    band_px = c.white_px * geometry.band_height_m / white_m
    rx, ry, rw, _ = c.red_bbox_px
    by, bh = c.blue_bbox_px[1], c.blue_bbox_px[3]
    whole = cut_sides(c, shape[1]) == (False, False)
    a, b = (x_px - rw / 3, x_px + rw / 3) if x_px is not None and whole else (rx, rx + rw)
    cx0, cx1 = int(np.floor(a + 0.5)), int(np.ceil(b - 0.5)) + 1
    step = _step(cx1 - cx0)
    pad = int(band_px) + 6
    h, w = shape[:2]
    x0, y0, x1, y1 = max(0, cx0), max(0, ry - pad), min(w, cx1), min(h, by + bh + pad)
    if x1 <= x0 or y1 <= y0:  # no column (or no row: no band rows to find)
        return None
    return x0, y0, x1, y1, step, a, b


def measure_rows_all(
    bgr: np.ndarray, cands: Sequence[Candidate], gains: Gains, geometry: LandmarkGeometry,
    xs_px: Sequence[Optional[float]],
) -> List[Optional[Rows]]:
    """:func:`measure_rows` of every candidate of a frame (``xs_px``: each one's ``x_px``).

    The candidates' tiles are stacked one below the other, so the conversion to
    linear-light excess and the column weighting run once for all of them; each
    band's rows are then found on its own tile's profile, as for one candidate.
    """
    wins = [_row_window(bgr.shape, c, geometry, x) for c, x in zip(cands, xs_px)]
    tiles, weights = [], []
    for k, win in enumerate(wins):
        if win is None:
            continue
        x0, y0, x1, y1, step, a, b = win
        tile = bgr[y0:y1, x0:x1:step]
        # end columns count by the share of them inside [a, b]: the profile moves smoothly with x
        cols = x0 + step * np.arange(tile.shape[1])
        wgt = np.clip(np.minimum(cols + 0.5, b) - np.maximum(cols - 0.5, a), 0.0, 1.0).astype(np.float32)
        if wgt.sum() <= 0:
            wins[k] = None
            continue
        wgt *= len(wgt) / wgt.sum()
        tiles.append(tile)
        weights.append(wgt)
    if not tiles:
        return [None] * len(cands)
    offs = np.cumsum([0] + [t.shape[0] for t in tiles]).tolist()
    stack = np.zeros((offs[-1], max(t.shape[1] for t in tiles), 3), np.uint8)
    wst = np.zeros(stack.shape[:2], np.float32)
    for o, tile, wgt in zip(offs, tiles, weights):
        stack[o : o + tile.shape[0], : tile.shape[1]] = tile
        wst[o : o + tile.shape[0], : tile.shape[1]] = wgt
    er_all, eb_all = excess(stack, gains)
    er_all *= wst
    eb_all *= wst
    out: List[Optional[Rows]] = []
    j = 0
    for c, win in zip(cands, wins):
        if win is None:
            out.append(None)
            continue
        o, n, m = offs[j], tiles[j].shape[0], tiles[j].shape[1]
        out.append(_rows(c, geometry, win[1], er_all[o : o + n, :m], eb_all[o : o + n, :m]))
        j += 1
    return out


def _rows(c: Candidate, geometry: LandmarkGeometry, oy: int, er: np.ndarray, eb: np.ndarray) -> Optional[Rows]:
    """A candidate's :class:`Rows` from its weighted excess tiles (``oy``: the tiles' first frame row)."""
    white_m = geometry.height_m - 2 * geometry.band_height_m
    band_px = c.white_px * geometry.band_height_m / white_m
    f = 1
    ry, rh = c.red_bbox_px[1], c.red_bbox_px[3]
    by, bh = c.blue_bbox_px[1], c.blue_bbox_px[3]
    hb, hw = band_px / f, c.white_px / f
    r_exp = (ry + 0.5 * rh - oy) / f - 0.5
    b_exp = (by + 0.5 * bh - oy) / f - 0.5
    red = _band(er, er.mean(axis=1), r_exp, hb, hw, True)
    blue = _band(eb, eb.mean(axis=1), b_exp, hb, hw, False)
    if red is None or blue is None or not blue.inner > red.inner:
        return None
    white = blue.inner - red.inner
    k = 0.5 * geometry.band_height_m / white_m
    if abs(white - c.white_px / f) <= WHITE_MATCH * c.white_px / f:  # the inner edges are the body's own
        blue = _hidden(blue, _height(red, True) or 2 * k * white)
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
        math.nan if red.merged else 2.0 * (red.inner - red.centre) * f,
        math.nan if blue.merged else 2.0 * (blue.centre - blue.inner) * f,
    )


def _height(band: BandEdges, red: bool) -> float:
    """A band's height between its two edges (rows); 0 when merged (its outer edge is not its own)."""
    if band.merged:
        return 0.0
    return 2.0 * (band.inner - band.centre) if red else 2.0 * (band.centre - band.inner)


def _hidden(blue: BandEdges, expected_px: float) -> BandEdges:
    """The blue band, marked merged when it is seen shorter than ``SHORT_BAND`` of ``expected_px``.

    A nearer robot's body in front hides the lower part of a landmark behind it:
    the blue band's outer edge is then the occluder's, and the mean of its edges
    sits too high (L short, range long, by up to ~10 %). Both bands are 15 mm on
    one cylinder at one depth, so the red band's height (or, when it merged,
    15/40 of the white body's) is what the blue one should measure. A red band
    cannot be hidden so: whatever hides its top hides the white body below it.
    """
    if blue.merged or _height(blue, False) >= SHORT_BAND * expected_px:
        return blue
    return dataclasses.replace(blue, merged=True)


def _band(p2d: np.ndarray, p: np.ndarray, expected: float, hb: float, hw: float, red: bool):
    """:func:`.edges.band_rows` around the row of strongest colour near ``expected`` (``p``: the row profile)."""
    n = p2d.shape[0]
    lo, hi = max(0, int(expected - 0.5 * hb - 3)), min(n, int(expected + 0.5 * hb + 4))
    if hi <= lo:
        return None
    prof = p[lo:hi]  # rows' means do not depend on the other rows
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
        return band_rows(p2d, mid - half, mid + half, True, mid + into_white, mid - beyond, p)
    return band_rows(p2d, mid - half, mid + half, False, mid - into_white, mid + beyond, p)


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

    Both bands' limbs are measured (:func:`.edges.limb`); they are one cylinder's
    outline, so when they disagree the inner one wins (a same-coloured band beside
    it only ever widens a band). ``x_px`` is the outline's centre, the column the
    model expects (:func:`.model.axis_bearing` takes it to the axis), placed from
    the limb by :func:`outline_centre`.
    """
    cut_left, cut_right = cut_sides(c, bgr.shape[1])
    if cut_left == cut_right:
        return None
    white_m = geometry.height_m - 2 * geometry.band_height_m
    band_px = rows.white_px * geometry.band_height_m / white_m
    rx, _, rw, _ = c.red_bbox_px
    cx_px = 0.5 * (bgr.shape[1] - 1)
    d = fy_px * white_m / max(rows.white_px, 1e-3) + geometry.radius_m
    half = rows.white_px * geometry.radius_m / white_m * (1.0 - geometry.radius_m / d)
    reach = round(2 * half) + 4
    edges = []
    for y_c, is_red in ((rows.red_y_px, True), (rows.blue_y_px, False)):
        y0, y1 = int(y_c - 0.3 * band_px), int(y_c + 0.3 * band_px) + 1
        x0, x1 = (rx - 4, rx + rw + reach) if cut_left else (rx - reach, rx + rw + 4)
        tile, ox, _ = _tile(bgr, x0, y0, x1, y1, row_step=_step(y1 - y0))
        er, eb = excess(tile, gains)
        lin_sum = np.maximum(linear_table()[tile].sum(axis=2), 1e-3)
        q = ((er if is_red else eb) / lin_sum).mean(axis=0)  # chromaticity: shading does not move it
        n = len(q)
        if n < 4:
            continue
        if cut_left:  # the right limb is natural: start inside, run right
            core = max(0, min(n - 1, int(rx + rw - ox) - int(half)))
        else:
            core = max(0, min(n - 1, int(rx - ox) + int(half)))
        level = float(np.median(q[max(0, core - 2) : core + 3]))
        edges.append(ox + limb(q, core, n - 1 if cut_left else 0, level))
    edges = [e for e in edges if math.isfinite(e)]
    if not edges:
        return None
    if len(edges) == 2 and abs(edges[0] - edges[1]) <= LIMB_AGREE_PX:
        edge = 0.5 * (edges[0] + edges[1])
    else:
        edge = min(edges) if cut_left else max(edges)
    x = outline_centre(edge, cut_left, cx_px, fy_px, rows.white_px, geometry)
    if not rx - half <= x <= rx + rw + half:  # no limb where the structure said: keep the moments
        return None
    return x, LIMB_SIGMA_X_PX


def outline_centre(
    limb_px: float, right: bool, cx_px: float, f_px: float, white_px: float, geometry: LandmarkGeometry
) -> float:
    """Image column of the cylinder's outline centre, from one limb's column.

    The outline spans the tangent rays at ``φ ± α`` (φ the axis's angle to the
    right of the optical axis, α = asin(r/d)), so the other limb lies at
    ``tan(φ_l ∓ 2α)``: off the axis the outline is wider than ``2·f·r/d`` by about
    1/cos²φ, which half a silhouette taken from the white height would miss.
    The range d comes from the white height (measured on the near surface, depth
    ``(d − r)·cos φ``). The principal point is taken at the frame centre and
    fx = fy: an error of a few pixels in either changes the result by hundredths
    of a pixel.
    """
    white_m = geometry.height_m - 2 * geometry.band_height_m
    z_m = f_px * white_m / max(white_px, 1e-3)
    phi_l = math.atan((limb_px - cx_px) / f_px)
    phi = phi_l
    for _ in range(OUTLINE_ITERATIONS):
        d = z_m / math.cos(phi) + geometry.radius_m
        alpha = math.asin(min(1.0, geometry.radius_m / d))
        phi = phi_l - alpha if right else phi_l + alpha
    other = math.tan(phi - alpha if right else phi + alpha)
    return cx_px + 0.5 * f_px * (math.tan(phi_l) + other)
