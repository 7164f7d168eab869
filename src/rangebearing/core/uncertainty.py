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
* a band whose outer edge merged with a same-coloured background is placed
  from its inner edge and the white body's height: ``MERGED_PX``;
* a partly hidden landmark's edges are seen over a part of the curve:
  ``HIDDEN_PX`` per unit of hidden share;
* a floor: ``EDGE_FLOOR_PX`` per band, and the model's own error after
  calibration (``MODEL_FLOOR``, relative; the fit's residuals are ~0.1 %).

Bearing. ``θ = atan(−x_n)``, so ``σ_θ = cos²θ · σ_x / f``. ``σ_x`` combines the
column measurement's own error (moments of a whole landmark, or a limb plus
half a silhouette), the disagreement of the red and the blue band's columns
(``|x_red − x_blue|/2``, the same two-estimator argument: a neighbour's band
beside one of them, a shadow across one, shows there), shading across the
cylinder (``SHADING_SHARE`` of the silhouette width), a hidden-share term, a
landmark cut on both sides (split from touching neighbours: ``SPLIT_SHARE`` of
its width) and a floor for the outline correction and the undistortion
(``BEARING_FLOOR_RAD``).

What the terms cannot see is a gross error (a neighbour's band taken for this
one's); ``docs/detection.md`` lists the known ones.
"""

from __future__ import annotations

import math
from typing import Tuple

NOISE_SHARE = 0.5  # column-scatter standard error of the inner edges → the spacing (two edges averaged)
EDGE_FLOOR_PX = 0.12  # per band centre, full-resolution pixels: a colour plane sampled at 2 px (Bayer, 4:2:0)
MERGED_PX = 0.5  # a band placed from its inner edge and the white height (heights on a curved surface)
MODEL_FLOOR = 0.001  # relative range error left after calibration
HIDDEN_PX = 0.5  # extra px of L per unit of hidden share (curvature of the edges over the visible part)
BEARING_FLOOR_RAD = math.radians(0.012)
SHADING_SHARE = 0.006  # column bias from shading across the cylinder, share of the silhouette width
HIDDEN_SHARE = 0.1  # column error per unit of hidden share, in silhouette widths (the visible part's centre)
SPLIT_SHARE = 0.04  # column error of a landmark cut on both sides (split between neighbours), share of its width


def row_spread_px(
    moment_red_px: float, edge_red_px: float, red_merged: bool,
    moment_blue_px: float, edge_blue_px: float, blue_merged: bool,
) -> float:
    """One-sigma error (px) of the band spacing from the two row estimators of each band.

    A band measured both ways contributes ``(moment − edge)²/4``; a merged band, whose
    moment is not its own, contributes ``MERGED_PX²`` instead.
    """
    red = MERGED_PX**2 if red_merged else 0.25 * (moment_red_px - edge_red_px) ** 2
    blue = MERGED_PX**2 if blue_merged else 0.25 * (moment_blue_px - edge_blue_px) ** 2
    return math.sqrt(red + blue)


def range_sigma_m(
    range_m: float, c_m: float, l_px: float, sigma_l_px: float, visible: float, spread_l_px: float = 0.0
) -> float:
    """One-sigma range error (m) of a reading at ``range_m`` from band spacing ``l_px``.

    ``sigma_l_px`` is the column scatter's standard error, ``spread_l_px`` the
    estimators' disagreement (:func:`row_spread_px`).
    """
    hidden = HIDDEN_PX * (1.0 - min(1.0, visible))
    s_l = math.sqrt((NOISE_SHARE * sigma_l_px) ** 2 + spread_l_px**2 + 2 * EDGE_FLOOR_PX**2 + hidden**2)
    spacing = max(range_m - c_m, 0.0) * s_l / max(l_px, 1e-6)
    return math.hypot(spacing, MODEL_FLOOR * range_m)


def bearing_sigma_rad(
    bearing_rad: float, sigma_x_px: float, width_px: float, fx_px: float, visible: float = 1.0,
    spread_x_px: float = 0.0, cut_both: bool = False,
) -> float:
    """One-sigma bearing error (rad) of a landmark ``width_px`` wide whose column is known to ``sigma_x_px``.

    ``spread_x_px`` is half the difference of the red and blue bands' columns;
    ``cut_both``: the landmark ends at a neighbour on both sides.
    """
    hidden = HIDDEN_SHARE * (1.0 - min(1.0, visible)) * width_px / max(visible, 0.3)
    split = SPLIT_SHARE * width_px if cut_both else 0.0
    s_x = math.sqrt(sigma_x_px**2 + spread_x_px**2 + (SHADING_SHARE * width_px) ** 2 + hidden**2 + split**2)
    return math.hypot(math.cos(bearing_rad) ** 2 * s_x / fx_px, BEARING_FLOOR_RAD)


def reading_sigma(
    range_m: float, bearing_rad: float, l_px: float, sigma_l_px: float, sigma_x_px: float, width_px: float,
    visible: float, c_m: float, fx_px: float, spread_l_px: float = 0.0, spread_x_px: float = 0.0,
    cut_both: bool = False,
) -> Tuple[float, float]:
    """``(range_sigma_m, bearing_sigma_rad)`` of one reading."""
    return (
        range_sigma_m(range_m, c_m, l_px, sigma_l_px, visible, spread_l_px),
        bearing_sigma_rad(bearing_rad, sigma_x_px, width_px, fx_px, visible, spread_x_px, cut_both),
    )
