"""Where a candidate's bands are, to a fraction of a pixel: rows from band edges, columns from limbs.

Rows: each band's two edges by the two-level integral of :mod:`.edges`, over
the landmark's own columns, so a neighbour beside it does not count; where the
camera's colour denoise or 4:2:0 chroma bled the band's colour into the white
body, the edges are taken from luma, which keeps full resolution. A band
whose outer edge merges with a same-coloured background, or a blue band whose
lower part a nearer robot hides, is placed from its inner edge and the white
body's height instead.

Columns (:mod:`.limbs`, re-exported here): a landmark seen whole is measured by the
saturation-weighted moments of :mod:`.refine`; one cut on a side is placed from its other limb.
"""

from __future__ import annotations

import dataclasses
import math
from typing import List, Optional, Sequence, Tuple

import numpy as np

from .._compat import frozen
from .band_fit import TALL_WHITE, band_fits, band_height, hidden_blue, misfit, overtall, white_clear
from .band_seed import body_side
from .band_seed import seeded_band as _band
from .color import Gains
from .column_scatter import Scatter, column_sigmas
from .edges import BandEdges, excess_luma, luma_edge, mean_along
from .limbs import CENTROID_SIGMA_X_PX, cut_sides, measure_columns, outline_centre, thin_step
from .structure import Candidate
from .types import LandmarkGeometry

MISFIT_SLACK = 0.05  # the luma may spoil the proportion by this much (band heights' own scatter)
BLED_PX = 0.25  # a luma inner edge this far from the chroma one shows the camera bleeds chroma
WHITE_MATCH = 0.1  # a short blue band is judged only when the white height agrees this well with the search's


@frozen
class Rows:
    """A candidate's band centres (rows, full-resolution pixels) and the white body's height.

    ``red_merged``/``blue_merged``: the band is placed from its inner edge and the white height, because its
    outer edge is not its own (merged with a background of its colour, or hidden). ``red_px``/``blue_px``:
    each band's height between its two measured edges (NaN when merged). ``red_luma``/``blue_luma``: its
    inner edge was taken from luma (the camera bleeds chroma into the white body). ``red_fits``/``blue_fits``:
    its edges span 15/40 of the white height within ``BAND_FIT`` (always for a merged band, placed from
    that height): :meth:`band_y` then takes the edges' row alone.
    """

    red_y_px: float
    blue_y_px: float
    white_px: float
    sigma_l_px: float
    red_merged: bool
    blue_merged: bool
    red_px: float = math.nan
    blue_px: float = math.nan
    red_luma: bool = False
    blue_luma: bool = False
    red_fits: bool = True
    blue_fits: bool = True

    def band_y(self, red: bool, moment_y_px: float) -> float:
        """The band's row (full-resolution pixels): its edges' row where its edges fit the landmark,
        else the mean of that and the band's moment ``moment_y_px``.

        The edges' row beats the chroma moment wherever the band's edges are its own: a camera's
        chroma bleed pulls the moment into the bright white body (L 1-1.7 % short under the
        photoreal camera) and a dark, faintly tinted thing beyond the band pulls it out. Where a
        band's two edges span a height off the landmark's 15/40, one of them is not the band's
        (a shadow, a fringe, a neighbour's part): the moment, measured another way, halves that
        error.
        """
        edge_y, fits = (self.red_y_px, self.red_fits) if red else (self.blue_y_px, self.blue_fits)
        return edge_y if fits else 0.5 * (moment_y_px + edge_y)


def measure_rows(
    bgr: np.ndarray, c: Candidate, gains: Gains, geometry: LandmarkGeometry, x_px: Optional[float] = None
) -> Optional[Rows]:
    """Band centre rows of a candidate, or ``None`` when a band shows no colour step at the white body.

    The profile is taken over the middle two thirds of the columns around ``x_px`` (the landmark's
    measured centre, when it is seen whole; limbs curve and darken), so a full scan and a tracking
    window use the same columns.
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
    step = thin_step(cx1 - cx0)
    pad = int(band_px) + 6
    h, w = shape[:2]
    x0, y0, x1, y1 = max(0, cx0), max(0, ry - pad), min(w, cx1), min(h, by + bh + pad)
    if x1 <= x0 or y1 <= y0:  # no column (or no row: no band rows to find)
        return None
    return x0, y0, x1, y1, step, a, b


def measure_rows_all(
    bgr: np.ndarray, cands: Sequence[Candidate], gains: Gains, geometry: LandmarkGeometry,
    xs_px: Sequence[Optional[float]], column_sigma: bool = True,
) -> List[Optional[Rows]]:
    """:func:`measure_rows` of every candidate of a frame (``xs_px``: each one's ``x_px``).

    ``column_sigma=False`` skips the column-scatter noise of the edges (``sigma_l_px``
    is then NaN): tracking keeps the one its last full scan measured.

    The candidates' tiles are stacked one below the other, so the conversion to
    linear-light excess and the column weighting run once for all of them; each
    band's rows are then found on its own tile's profile, as for one candidate.
    """
    wins = [_row_window(bgr.shape, c, geometry, x) for c, x in zip(cands, xs_px)]
    tiles, weights = [], []
    live = [k for k, win in enumerate(wins) if win is not None]
    if live:
        # end columns count by the share of them inside [a, b]: the profile moves smoothly with x
        # (every window's column weights in one go: the same element-wise arithmetic as one at a time)
        x0s, steps, lo, hi = (np.array([wins[k][i] for k in live]) for i in (0, 4, 5, 6))
        widths = np.array([-(-(wins[k][2] - wins[k][0]) // wins[k][4]) for k in live])
        first = np.cumsum(widths) - widths
        local = np.arange(int(widths.sum())) - np.repeat(first, widths)  # each window's column number
        cols = np.repeat(x0s, widths) + np.repeat(steps, widths) * local
        wgt_all = np.clip(np.minimum(cols + 0.5, np.repeat(hi, widths)) - np.maximum(cols - 0.5, np.repeat(lo, widths)),
                          0.0, 1.0).astype(np.float32)
        for k, f, n in zip(live, first.tolist(), widths.tolist()):
            wgt = wgt_all[f : f + n]
            total = np.add.reduce(wgt)
            if total <= 0:
                wins[k] = None
                continue
            wgt *= n / total
            x0, y0, x1, y1, step = wins[k][:5]
            tiles.append(bgr[y0:y1, x0:x1:step])
            weights.append(wgt)
    if not tiles:
        return [None] * len(cands)
    offs = np.cumsum([0] + [t.shape[0] for t in tiles]).tolist()
    stack = np.zeros((offs[-1], max(t.shape[1] for t in tiles), 3), np.uint8)
    wst = np.zeros(stack.shape[:2], np.float32)
    for o, tile, wgt in zip(offs, tiles, weights):
        stack[o : o + tile.shape[0], : tile.shape[1]] = tile
        wst[o : o + tile.shape[0], : tile.shape[1]] = wgt
    er_all, eb_all, lu_all = excess_luma(stack, gains)
    er_all *= wst
    eb_all *= wst
    lu_all *= wst
    out: List[Optional[Rows]] = []
    later: List[tuple] = []  # the bands' column scatter, measured for all bands at once (core/column_scatter.py)
    j = 0
    for c, win in zip(cands, wins):
        if win is None:
            out.append(None)
            continue
        o, n, m = offs[j], tiles[j].shape[0], tiles[j].shape[1]
        got = len(later)
        out.append(_rows(c, geometry, win[1], er_all[o : o + n, :m], eb_all[o : o + n, :m], column_sigma,
                         lu_all[o : o + n, :m], later if column_sigma else None))
        if len(later) > got:
            later[-1] += (len(out) - 1, o, n, m)
        j += 1
    specs: List[Scatter] = [(b, o, n, m, *bands[b], b == 0) for *bands, _, _, o, n, m in later for b in (0, 1)]
    sigmas = column_sigmas((er_all, eb_all), specs)
    for (_, _, factor, k, *_), s_red, s_blue in zip(later, sigmas[0::2], sigmas[1::2]):
        out[k] = dataclasses.replace(out[k], sigma_l_px=math.hypot(s_red, s_blue) * factor)
    return out


def _rows(c: Candidate, geometry: LandmarkGeometry, oy: int, er: np.ndarray, eb: np.ndarray,
          column_sigma: bool = True, lu: Optional[np.ndarray] = None, later: Optional[list] = None) -> Optional[Rows]:
    """A candidate's :class:`Rows` from its weighted excess tiles and luma tile ``lu``
    (``oy``: the tiles' first frame row). ``later``: a list the bands' scatter and the sigma's factor go to,
    ``sigma_l_px`` then NaN (the caller measures all bands' column scatter at once)."""
    column_sigma = column_sigma and later is None
    white_m = geometry.height_m - 2 * geometry.band_height_m
    band_px = c.white_px * geometry.band_height_m / white_m
    f = 1
    ry, rh = c.red_bbox_px[1], c.red_bbox_px[3]
    by, bh = c.blue_bbox_px[1], c.blue_bbox_px[3]
    hb, hw = band_px / f, c.white_px / f
    r_exp = (ry + 0.5 * rh - oy) / f - 0.5
    b_exp = (by + 0.5 * bh - oy) / f - 0.5
    red = _band(er, mean_along(er, 1), r_exp, hb, hw, True, column_sigma)
    blue = _band(eb, mean_along(eb, 1), b_exp, hb, hw, False, column_sigma)
    lp = None if lu is None or red is None or blue is None else mean_along(lu, 1)  # a merged band's edge: the body's
    red, blue = (red, blue) if lp is None else (body_side(lp, red, True, hb), body_side(lp, blue, False, hb))
    if red is None or blue is None or not blue.inner > red.inner:
        return None
    white, k = blue.inner - red.inner, 0.5 * geometry.band_height_m / white_m
    cw, tol = c.white_px / f, WHITE_MATCH * c.white_px / f  # inner edges (chroma or luma) this close: the body's
    blue = hidden_blue(blue, band_height(red, True) or 2 * k * white) if abs(white - cw) <= tol else blue
    luma = (False, False)
    if lp is not None and not (red.merged and blue.merged):
        l_red, l_blue, l_white = _luma_edges(lp, red, blue, 2 * k * white)
        if abs(l_white - cw) <= tol:
            l_blue = hidden_blue(l_blue, band_height(l_red, True) or 2 * k * l_white)
        # the landmark's proportions decide: chroma bleed makes the bands too tall for the white body
        # (the luma restores 15/40), while a luma edge taken from a shadow or a part in front spoils them
        if misfit(l_red, l_blue, l_white, 2 * k) <= misfit(red, blue, white, 2 * k) + MISFIT_SLACK:
            luma = (l_red.inner != red.inner, l_blue.inner != blue.inner)
            red, blue, white = l_red, l_blue, l_white
    vouched = abs(white - cw) <= TALL_WHITE * cw and white_clear(lp, red, blue)  # the white height is the body's
    red, blue = overtall(red, blue, 2 * k * white, vouched)
    red_y = red.inner - k * white if red.merged else red.centre
    blue_y = blue.inner + k * white if blue.merged else blue.centre
    factor = 1.0 + (2 * k if red.merged or blue.merged else 0.0)
    sigma = float(np.hypot(red.sigma, blue.sigma)) * factor
    later is None or later.append((red.scatter, blue.scatter, factor))
    return Rows(
        oy + (red_y + 0.5) * f - 0.5,
        oy + (blue_y + 0.5) * f - 0.5,
        white * f,
        sigma * f,
        red.merged,
        blue.merged,
        math.nan if red.merged else band_height(red, True) * f,
        math.nan if blue.merged else band_height(blue, False) * f,
        luma[0],
        luma[1],
        band_fits(red, True, 2 * k * white),
        band_fits(blue, False, 2 * k * white),
    )


def _luma_edges(p: np.ndarray, red: BandEdges, blue: BandEdges, band_px: float
                ) -> Tuple[BandEdges, BandEdges, float]:
    """The bands with their edges moved to the luma's (:func:`.edges.luma_edge`) where taken.

    Inner edges first: the white body is always brighter than a band. Where a band's inner
    luma edge lies ``BLED_PX`` or more from its chroma edge the camera bleeds chroma, into a
    light background too, so the outer edge is taken from luma as well when the background's
    luma differs from the band's; elsewhere the chroma outer edge stands (a background's own
    luma steps, a landmark behind, would only add error). A band's centre is the mean of its
    two edges; a merged band is placed from its inner edge and the white height, so it
    follows both through the caller's formula.
    """
    bands = []
    for band, down in ((red, True), (blue, False)):
        inner = luma_edge(p, band.inner, down, band_px, True)
        if inner is None and band_height(band, down) > band_px:  # bled 3-4 px (video coding): the band as it bled
            inner = luma_edge(p, band.inner, down, band_height(band, down), True)
        bled = inner is not None and abs(inner - band.inner) >= BLED_PX
        inner = band.inner if inner is None else inner
        if band.merged:
            band = BandEdges(band.centre, inner, True, band.sigma, band.scatter)  # dataclasses.replace, minus its cost
        else:
            outer = 2.0 * band.centre - band.inner
            found = luma_edge(p, outer, not down, band_px, False) if bled else None
            outer = outer if found is None else found
            band = BandEdges(0.5 * (inner + outer), inner, False, band.sigma, band.scatter)
        bands.append(band)
    return bands[0], bands[1], bands[1].inner - bands[0].inner


__all__ = ["CENTROID_SIGMA_X_PX", "Rows", "cut_sides", "measure_columns", "measure_rows", "measure_rows_all",
           "outline_centre"]
