"""One-sigma uncertainty of a reading, propagated from the measurement through the model.

Range. With ``d = S/(L_n·cos θ) + c`` a small error δL in the band spacing
moves the range by ``−(d − c)·δL/L``, so ``σ_d = (d − c)·σ_L/L``; ``σ_L``
combines the scatter of the band edges from column to column (noise and
texture as this very frame shows them, from :mod:`.edges`) with a floor for
what a single frame cannot show: the sub-pixel bias of the band measurement
(``EDGE_FLOOR_PX`` per band) and the model's own error after calibration
(``MODEL_FLOOR``, relative), and, dominant up close, where on the curved
near surface the bands sit (the ``c ≈ (π/4)·r`` offset; ``DEPTH_SHARE`` of
the radius). A landmark placed from one band's inner edge
(merged) or from one limb (cut) carries the extra terms its geometry adds.

Bearing. ``θ = atan(−x_n)``, so ``σ_θ = cos²θ · σ_x / f``: ``σ_x`` is the
column measurement's (moments of a whole landmark, or a limb plus half a
silhouette), plus a floor for the cylinder outline correction and the
undistortion (``BEARING_FLOOR_RAD``).

The floors were set once so that on synthetic sets (JPEG and PNG, 0.15–2 m,
dim to bright, clutter, touching and hidden landmarks) |error| ≤ 2σ holds for
90–98 % of readings; ``tests/test_acceptance_crowd.py`` checks it on sets not
used to set them.
"""

from __future__ import annotations

import math
from typing import Tuple

EDGE_FLOOR_PX = 0.04  # per band centre, full-resolution pixels
EDGE_SCATTER = 0.5  # the inner edge's scatter → the band centre's (two edges, two estimates averaged)
MODEL_FLOOR = 0.002  # relative range error left after calibration
DEPTH_SHARE = 0.06  # where on the curved near surface the bands are measured: this share of the radius
HIDDEN_PX = 0.25  # extra px of L per unit of hidden share (curvature of the edges over the visible part)
BEARING_FLOOR_RAD = math.radians(0.012)
SHADING_SHARE = 0.008  # column bias from shading across the cylinder, share of the silhouette width
HIDDEN_SHARE = 0.05  # column error per unit of hidden share, in silhouette widths (the visible part's centre)


def range_sigma_m(
    range_m: float, c_m: float, l_px: float, sigma_l_px: float, visible: float, radius_m: float = 0.0175
) -> float:
    """One-sigma range error (m) of a reading at ``range_m`` from band spacing ``l_px`` ± ``sigma_l_px``."""
    hidden = HIDDEN_PX * (1.0 - min(1.0, visible))
    s_l = math.sqrt((EDGE_SCATTER * sigma_l_px) ** 2 + 2 * EDGE_FLOOR_PX**2 + hidden**2)
    spacing = max(range_m - c_m, 0.0) * s_l / max(l_px, 1e-6)
    return math.sqrt(spacing**2 + (MODEL_FLOOR * range_m) ** 2 + (DEPTH_SHARE * radius_m) ** 2)


def bearing_sigma_rad(
    bearing_rad: float, sigma_x_px: float, width_px: float, fx_px: float, visible: float = 1.0
) -> float:
    """One-sigma bearing error (rad) of a landmark ``width_px`` wide whose column is known to ``sigma_x_px``."""
    hidden = HIDDEN_SHARE * (1.0 - min(1.0, visible)) * width_px / max(visible, 0.3)
    s_x = math.sqrt(sigma_x_px**2 + (SHADING_SHARE * width_px) ** 2 + hidden**2)
    return math.hypot(math.cos(bearing_rad) ** 2 * s_x / fx_px, BEARING_FLOOR_RAD)


def reading_sigma(
    range_m: float, bearing_rad: float, l_px: float, sigma_l_px: float, sigma_x_px: float, width_px: float,
    visible: float, c_m: float, fx_px: float,
) -> Tuple[float, float]:
    """``(range_sigma_m, bearing_sigma_rad)`` of one reading."""
    return (
        range_sigma_m(range_m, c_m, l_px, sigma_l_px, visible),
        bearing_sigma_rad(bearing_rad, sigma_x_px, width_px, fx_px, visible),
    )
