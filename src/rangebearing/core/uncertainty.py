"""One-sigma uncertainty of a reading, propagated from the measurement through the model.

Range. With ``d = S/(L_n·cos θ) + c`` a small error δL in the band spacing
moves the range by ``−(d − c)·δL/L``, so ``σ_d = (d − c)·σ_L/L``. ``σ_L``
combines what this very frame shows about its own measurement:

* **pixel noise**: the scatter of the band edges from column to column
  (:mod:`.edges`), as a standard error, ``NOISE_SHARE`` of it reaching the
  spacing (each band's centre averages two edges and the chroma moment);
* **disagreement of independent estimators** (:func:`row_spread_px`): each
  band's row is the mean of its chroma moment (gamma-encoded pixels) and of
  its edges' midpoint (linear light). Blur, a demosaiced Bayer mosaic's colour
  fringes, JPEG chroma, a dark neighbour pull the two apart by different
  amounts; for two estimates ``a`` and ``b`` with independent errors their
  mean's error has variance ``E[(a − b)²]/4``, so the observed ``(a − b)²/4``
  estimates it, frame by frame, without knowing which effect caused it. The
  column scatter cannot see these: they shift every column alike;
* **the colour's own blur** (:func:`chroma_blur_px`): where a camera keeps
  colour at a lower resolution than brightness (a Bayer demosaic, 4:2:0 or JPEG
  chroma, colour denoise), band colour bleeds into the bright white body more
  than into the background, and both row estimators move with it; the inner
  edges' width in colour beyond their width in luma measures it;
* a band whose outer edge merged with a same-coloured background is placed
  from its inner edge and the white body's height: ``MERGED_PX``;
* a partly hidden landmark's edges are seen over a part of the curve: ``HIDDEN_SHARE_L`` of L per unit
  of hidden share (``CUT_HIDDEN_SHARE_L`` if cut: :mod:`.arc` scales its rows for the part seen); a landmark
  cut on one side or both (a neighbour, the frame's edge): ``CUT_SHARE_L``/``SPLIT_SHARE_L`` of L;
* an over-exposed white body (clipped at full scale) swallows the mixed pixels of the
  bands' inner edges, by up to a pixel and the blur, so both bands read short towards the
  body and L long; nothing else in the frame shows it (clipping even hides the noise):
  ``CLIPPED_PX`` per band centre times the clipped share of the body (:func:`white_clipped`);
* a floor: ``EDGE_FLOOR_PX`` per band, and the model's own error after calibration (``MODEL_FLOOR``, relative).

Bearing. ``θ = atan(−x_n)``, so ``σ_θ = cos²θ · σ_x / f``. ``σ_x`` combines the column measurement's own
error (moments of a whole landmark, or a limb plus half a silhouette), the disagreement of the red and the
blue band's columns (``|x_red − x_blue|/2``, the same two-estimator argument: a neighbour's band beside one
of them, a shadow across one, shows there), shading across the
cylinder (``SHADING_SHARE`` of the silhouette width), a hidden-share term (``CUT_HIDDEN_SHARE`` if cut:
the hidden part may be the limb it is placed from), a landmark cut on one side (placed from its other limb:
``CUT_SHARE`` of its width) or both (split from touching neighbours: ``SPLIT_SHARE``) and a floor
for the outline correction and the undistortion (``BEARING_FLOOR_RAD``).

The shares are set so that |error| ≤ 2σ holds for 90–98 % of the readings on
every synthetic preset at once, photoreal included (docs/detection.md).
What the terms cannot see is a gross error (a neighbour's band taken for this
one's); ``docs/detection.md`` lists the known ones.
"""

from __future__ import annotations

import math
from typing import List, Optional, Sequence, Tuple

import cv2
import numpy as np

from .color import Gains
from .edges import excess_luma, mean_along
from .types import LandmarkGeometry

# range: terms of the band spacing's error (px), each in quadrature
NOISE_SHARE = 0.55  # column-scatter standard error of the inner edges → the spacing
SPREAD_SHARE = 2.5  # share of the row estimators' disagreement (row_spread_px) that is error
FIT_SPREAD = 0.21  # share of |moment − edge| a row from its edges alone errs by (the mean of both: 0.5)
MOMENT_PX = 0.22  # the chroma moment's own error (px): the part of |moment − edge| a row from its edges lacks
EDGE_FLOOR_PX = 0.01  # per band centre, full-resolution pixels: sampling, the outline's curve
CHROMA_SHARE = 0.14  # per band centre, share of the colour's own blur (chroma_blur_px)
CLIPPED_PX = 0.2  # per band centre, a wholly clipped white body's pull on the inner edges
CLIP_LEVEL = 248  # an 8-bit channel this bright is clipped (JPEG rings a clipped area a few levels down)
MERGED_PX = 0.55  # a band placed from its inner edge and the white height (heights on a curved surface)
HIDDEN_SHARE_L = 0.164  # share of L per unit of hidden share (the edges' curve over the visible part)
CUT_HIDDEN_SHARE_L = 0.027  # the same of a cut landmark, whose rows arc.py scales for the part seen
SPLIT_SHARE_L = 0.00231  # share of L: a landmark cut on both sides (split between neighbours)
CUT_SHARE_L = 0.00472  # share of L: a landmark cut on one side (a neighbour or the frame's edge)
MODEL_FLOOR = 0.0002  # relative range error left after calibration
# bearing: terms of the column's error (px)
COLUMN_SHARE = 1.21  # of the column measurement's own error (moments, or a limb and half a silhouette)
SPREAD_X_SHARE = 2.58  # of half the red and blue bands' column difference
SHADING_SHARE = 0.00255  # column bias from shading across the cylinder, share of the silhouette width
HIDDEN_SHARE = 0.289  # column error per unit of hidden share, in silhouette widths (the visible part's centre)
CUT_HIDDEN_SHARE = 0.72  # the same of a cut landmark (placed from a limb: the hidden part may be that limb's)
SPLIT_SHARE = 0.016  # column error of a landmark cut on both sides (split between neighbours), share of its width
CUT_SHARE = 0.034  # column error of a landmark cut on one side (placed from its other limb), share of its width
BEARING_FLOOR_RAD = 5e-5  # 0.003°: the outline correction and the undistortion
EDGE_WINDOW_PX = 5  # rows searched each side of a band's expected inner edge for its steepest step
EDGE_HALF_PX = 3  # rows each side of that step whose derivative makes the edge's width
BAND_SHARE = 15.0 / 55.0  # a band's height over the band spacing


def _edge_width(p: np.ndarray, at: float, rising: bool) -> float:
    """Second-moment width (rows) of the step of profile ``p`` nearest row ``at``; NaN when there is none.

    The derivative's samples are weighted as they are, negative ones included: clipping them at
    zero would give a noisy profile's tails a positive second moment, so a sharp but noisy edge
    (colour excess is a difference of channels: noisier than luma) would read wider than it is.
    """
    lo, hi = max(0, int(at) - EDGE_WINDOW_PX), min(len(p) - 1, int(at) + EDGE_WINDOW_PX)
    if hi - lo < 3:
        return math.nan
    d = np.diff(p[lo : hi + 1]) if rising else -np.diff(p[lo : hi + 1])
    dl = d.tolist()
    j = dl.index(max(dl))  # np.argmax: the first largest
    dl = dl[max(0, j - EDGE_HALF_PX) : j + EDGE_HALF_PX + 1]
    base = max(0.0, min(dl[0], dl[-1]))  # a shading slope under the step is no edge
    dl = [v - base for v in dl]
    total = math.fsum(dl)
    if total <= 1e-9:
        return math.nan
    m = math.fsum(k * v for k, v in enumerate(dl)) / total
    second = math.fsum((k - m) * (k - m) * v for k, v in enumerate(dl))
    return math.sqrt(max(second / total, 0.0))


def chroma_blur_px(
    bgr: np.ndarray, red_xy_px: Tuple[float, float], blue_xy_px: Tuple[float, float], width_px: float, gains: Gains,
) -> float:
    """How much blurrier the colour is than the brightness at the bands' inner edges (px, ≥ 0).

    The band rows come from colour (chroma moments, excess edges); where a camera keeps
    colour at a lower resolution than brightness (a Bayer mosaic's demosaic, 4:2:0 or
    JPEG chroma, the ISP's colour denoise) the band's colour bleeds into the white body
    by an amount the two row estimators share, so their disagreement cannot show it.
    The edges show it: each inner (band/white) edge's width in the band's colour excess
    and in luma, over the middle two thirds of the landmark's columns; the colour's own
    blur is ``sqrt(w_colour² − w_luma²)`` (blurs add in quadrature), averaged over the
    two bands (``w_colour² − w_luma²`` averaged over the bands before it is clipped at zero:
    on a camera with colour at luma's resolution the difference is noise around zero, and
    clipping each band's would read a blur where there is none). Luma sharpening narrows the
    luma edge, which counts as colour blur too: the colour planes are not sharpened.
    """
    return chroma_blur_all(bgr, [(red_xy_px, blue_xy_px, width_px)], gains)[0]


BlurWindow = Tuple[int, int, int, int, float, float]  # y0, y1, x0, x1 and the two inner edges' rows in it


def _blur_window(shape: Tuple[int, ...], red_xy_px: Tuple[float, float], blue_xy_px: Tuple[float, float],
                 width_px: float) -> Optional[BlurWindow]:
    """The frame region :func:`chroma_blur_px` reads and the inner edges' rows in it; ``None`` when too small."""
    h, w = shape[:2]
    x = 0.5 * (red_xy_px[0] + blue_xy_px[0])
    x0, x1 = int(max(0, x - width_px / 3)), int(min(w, x + width_px / 3 + 1))
    y_r, y_b = red_xy_px[1], blue_xy_px[1]
    half = 0.5 * BAND_SHARE * (y_b - y_r)
    y0, y1 = int(max(0, y_r + half - EDGE_WINDOW_PX - 2)), int(min(h, y_b - half + EDGE_WINDOW_PX + 3))
    if x1 <= x0 or y1 - y0 < 8:
        return None
    return y0, y1, x0, x1, y_r + half - y0, y_b - half - y0


def chroma_blur_all(bgr: np.ndarray, bands: Sequence[Tuple[Tuple[float, float], Tuple[float, float], float]],
                    gains: Gains) -> List[float]:
    """:func:`chroma_blur_px` of every ``(red_xy_px, blue_xy_px, width_px)`` of a frame, the same values.

    The landmarks' tiles are stacked one below the other, so the conversion to linear-light
    excess and luma runs once for all of them (it is per pixel: stacking changes no value);
    each tile's column means are then taken over its own columns only.
    """
    wins = [_blur_window(bgr.shape, r, b, w) for r, b, w in bands]
    live = [win for win in wins if win is not None]
    if not live:
        return [0.0] * len(wins)
    offs = np.cumsum([0] + [win[1] - win[0] for win in live]).tolist()
    stack = np.zeros((offs[-1], max(win[3] - win[2] for win in live), 3), np.uint8)
    for o, (y0, y1, x0, x1, _, _) in zip(offs, live):
        stack[o : o + y1 - y0, : x1 - x0] = bgr[y0:y1, x0:x1]
    er_all, eb_all, lu_all = excess_luma(stack, gains)
    out: List[float] = []
    j = 0
    for win in wins:
        if win is None:
            out.append(0.0)
            continue
        y0, y1, x0, x1, at_r, at_b = win
        rows, m = slice(offs[j], offs[j] + y1 - y0), x1 - x0
        j += 1
        luma = mean_along(lu_all[rows, :m], 1)
        blur2 = []
        for p, at, colour_rises in ((mean_along(er_all[rows, :m], 1), at_r, False),
                                    (mean_along(eb_all[rows, :m], 1), at_b, True)):
            wc, wl = _edge_width(p, at, colour_rises), _edge_width(luma, at, not colour_rises)
            if math.isfinite(wc) and math.isfinite(wl):
                blur2.append(wc * wc - wl * wl)
        out.append(math.sqrt(max(0.0, sum(blur2) / len(blur2))) if blur2 else 0.0)
    return out


def row_spread_px(
    moment_red_px: float, edge_red_px: float, red_merged: bool,
    moment_blue_px: float, edge_blue_px: float, blue_merged: bool,
    red_fits: bool = False, blue_fits: bool = False,
) -> float:
    """One-sigma error (px) of the band spacing from the two row estimators of each band.

    A band whose row is the mean of its moment and its edges' row contributes
    ``(moment − edge)²/4``; a band placed from its edges alone (``*_fits``: its edges span
    the landmark's band height, :meth:`.measure.Rows.band_y`) errs by less than that mean,
    ``FIT_SPREAD² · max(0, (moment − edge)² − MOMENT_PX²)``: the disagreement's square is the
    two estimators' errors' squares added, and the moment's own (its mask's sampling of a
    curved band, shading within it: ``MOMENT_PX``, about what a clean render of a lone landmark
    shows, where the edges are right to their noise) does not reach a row placed without it.
    A merged band, whose moment is not its own, contributes ``MERGED_PX²`` instead.
    """
    terms = []
    for moment, edge, merged, fits in ((moment_red_px, edge_red_px, red_merged, red_fits),
                                       (moment_blue_px, edge_blue_px, blue_merged, blue_fits)):
        d2 = (moment - edge) ** 2
        if merged:
            terms.append(MERGED_PX**2)
        elif fits:
            terms.append(FIT_SPREAD**2 * max(0.0, d2 - MOMENT_PX**2))
        else:
            terms.append(0.25 * d2)
    return math.sqrt(terms[0] + terms[1])


def white_clipped(bgr: np.ndarray, red_xy_px: Tuple[float, float], blue_xy_px: Tuple[float, float],
                  width_px: float) -> float:
    """Share (0-1) of the white body's pixels, between the bands and over the middle two thirds of
    its columns, clipped in every channel (at least ``CLIP_LEVEL``)."""
    h, w = bgr.shape[:2]
    half = 0.5 * BAND_SHARE * (blue_xy_px[1] - red_xy_px[1])
    y0, y1 = max(0, math.ceil(red_xy_px[1] + half)), min(h, math.floor(blue_xy_px[1] - half) + 1)
    x = 0.5 * (red_xy_px[0] + blue_xy_px[0])
    x0, x1 = int(max(0, x - width_px / 3)), int(min(w, x + width_px / 3 + 1))
    if y1 <= y0 or x1 <= x0 or bgr.ndim != 3:
        return 0.0
    roi = bgr[y0:y1, x0:x1]  # every channel >= CLIP_LEVEL counted by OpenCV (numpy's min over channels: 10x slower)
    return cv2.countNonZero(cv2.inRange(roi, (CLIP_LEVEL,) * 3, (255,) * 3)) / (roi.shape[0] * roi.shape[1])


def silhouette_share(visible: float, search_white_px: float, white_px: float, fy_px: float,
                     geometry: LandmarkGeometry) -> float:
    """``visible`` (the structure search's run width over the silhouette it expected) against the
    silhouette this landmark really has, at most 1.

    The search expects a silhouette ``diameter/white height`` times its white body's height in
    mask pixels (``search_white_px``, in full-resolution pixels). A cylinder's outline is
    narrower than that, by ``sqrt((d − r)/(d + r))`` at distance ``d`` (the white body's height
    is seen at its front, ``d − r``; the outline spans the tangents, ``2r/sqrt(d² − r²)``): 1.7 %
    at 1 m, 8 % at 0.2 m. So a whole landmark near the camera read 0.92-0.97 "visible"; with
    the white height measured at full resolution (``white_px``) and its range, it reads whole.
    """
    if visible >= 1.0 or white_px <= 0.0:
        return visible
    white_m = geometry.height_m - 2.0 * geometry.band_height_m
    r = geometry.radius_m
    d = fy_px * white_m / white_px + r
    outline = math.sqrt(max(d - r, 0.0) / (d + r))
    return min(1.0, visible * search_white_px / max(white_px * outline, 1e-6))


def range_sigma_m(
    range_m: float, c_m: float, l_px: float, sigma_l_px: float, visible: float, spread_l_px: float = 0.0,
    chroma_blur_px: float = 0.0, cut: Tuple[bool, bool] = (False, False), clipped: float = 0.0,
) -> float:
    """One-sigma range error (m) of a reading at ``range_m`` from band spacing ``l_px``.

    ``sigma_l_px`` is the column scatter's standard error, ``spread_l_px`` the
    estimators' disagreement (:func:`row_spread_px`), ``chroma_blur_px`` the colour's
    own blur (:func:`chroma_blur_px`), ``cut`` whether the landmark ends at a
    neighbour or the frame's edge on its left, right side, ``clipped`` the white body's clipped
    share (:func:`white_clipped`).
    """
    hidden = (CUT_HIDDEN_SHARE_L if any(cut) else HIDDEN_SHARE_L) * (1.0 - min(1.0, visible)) * l_px
    split = (SPLIT_SHARE_L if all(cut) else CUT_SHARE_L if any(cut) else 0.0) * l_px
    s_l = math.sqrt((NOISE_SHARE * sigma_l_px) ** 2 + (SPREAD_SHARE * spread_l_px) ** 2
                    + 2 * (EDGE_FLOOR_PX**2 + (CHROMA_SHARE * chroma_blur_px) ** 2 + (CLIPPED_PX * clipped) ** 2)
                    + hidden**2 + split**2)
    spacing = max(range_m - c_m, 0.0) * s_l / max(l_px, 1e-6)
    return math.hypot(spacing, MODEL_FLOOR * range_m)


def bearing_sigma_rad(
    bearing_rad: float, sigma_x_px: float, width_px: float, fx_px: float, visible: float = 1.0,
    spread_x_px: float = 0.0, cut: Tuple[bool, bool] = (False, False),
) -> float:
    """One-sigma bearing error (rad) of a landmark ``width_px`` wide whose column is known to ``sigma_x_px``.

    ``spread_x_px`` is half the difference of the red and blue bands' columns;
    ``cut``: the landmark ends at a neighbour or the frame's edge on its left, right side.
    """
    hidden = (CUT_HIDDEN_SHARE if any(cut) else HIDDEN_SHARE) * (1.0 - min(1.0, visible)) * width_px / max(visible, 0.3)
    split = (SPLIT_SHARE if all(cut) else CUT_SHARE if any(cut) else 0.0) * width_px
    s_x = math.sqrt((COLUMN_SHARE * sigma_x_px) ** 2 + (SPREAD_X_SHARE * spread_x_px) ** 2
                    + (SHADING_SHARE * width_px) ** 2 + hidden**2 + split**2)
    return math.hypot(math.cos(bearing_rad) ** 2 * s_x / fx_px, BEARING_FLOOR_RAD)


def reading_sigma(
    range_m: float, bearing_rad: float, l_px: float, sigma_l_px: float, sigma_x_px: float, width_px: float,
    visible: float, c_m: float, fx_px: float, spread_l_px: float = 0.0, spread_x_px: float = 0.0,
    cut: Tuple[bool, bool] = (False, False), chroma_blur_px: float = 0.0, clipped: float = 0.0,
) -> Tuple[float, float]:
    """``(range_sigma_m, bearing_sigma_rad)`` of one reading."""
    return (
        range_sigma_m(range_m, c_m, l_px, sigma_l_px, visible, spread_l_px, chroma_blur_px, cut, clipped),
        bearing_sigma_rad(bearing_rad, sigma_x_px, width_px, fx_px, visible, spread_x_px, cut),
    )
