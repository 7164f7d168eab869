"""Pair red bands with the blue band below them; reject everything that does not fit.

A landmark seen from the side is a cylinder of diameter D with band centres a
vertical distance S apart, so in the image the band centroids are about
``w·S/D`` pixels apart (w the band's width in pixels), one directly above the
other, with bands of similar width. Red boxes, blue posters, tinted floors and
misaligned red/blue pairs fail one of these tests.
"""

from __future__ import annotations

from typing import List, Tuple

import numpy as np

from .._compat import frozen
from .types import LandmarkGeometry


@frozen
class PairingLimits:
    """Tolerances on the landmark's image geometry (ratios, dimensionless)."""

    spacing_lo: float = 0.6  # measured/expected centroid spacing
    spacing_hi: float = 1.6
    width_ratio_min: float = 0.55  # narrower band / wider band
    max_dx: float = 0.4  # horizontal centroid offset / band width
    band_aspect_lo: float = 0.12  # band height / band width
    band_aspect_hi: float = 1.1
    slack_px: float = 2.0  # absolute slack for small, quantised blobs


DEFAULT_LIMITS = PairingLimits()


def _features(boxes: np.ndarray) -> np.ndarray:
    """(N, 4) float array of centre x, centre y, width, height (pixel centres at integers)."""
    b = np.asarray(boxes, np.float64).reshape(-1, 4)
    return np.column_stack((b[:, 0] + b[:, 2] / 2 - 0.5, b[:, 1] + b[:, 3] / 2 - 0.5, b[:, 2], b[:, 3]))


def _band_shaped(f: np.ndarray, lim: PairingLimits) -> np.ndarray:
    """Which boxes have a band's height-to-width ratio (a red wall or a speck does not)."""
    w = np.maximum(f[:, 2], 1.0)
    slack = lim.slack_px / w
    aspect = f[:, 3] / w
    return (aspect >= lim.band_aspect_lo - slack) & (aspect <= lim.band_aspect_hi + slack)


def pair_scores(
    red_boxes: np.ndarray, blue_boxes: np.ndarray, geometry: LandmarkGeometry, lim: PairingLimits = DEFAULT_LIMITS
) -> np.ndarray:
    """(R, B) array: how badly red box i over blue box j deviates from a landmark; ``inf`` if it cannot be one.

    A landmark's bands have similar widths w, the blue centre lies below the
    red one by about ``w·spacing/diameter``, and they are horizontally aligned.
    The score adds the log spacing ratio, the horizontal offset in widths and the
    log width ratio; 0 is a perfect landmark.
    """
    r, b = _features(red_boxes), _features(blue_boxes)
    rw, bw = np.maximum(r[:, 2:3], 1.0), np.maximum(b[:, 2], 1.0)[None, :]
    w = np.maximum(rw, bw)
    narrow = np.minimum(rw, bw)
    dy = b[None, :, 1] - r[:, 1:2]
    expected = w * (geometry.band_spacing_m / geometry.diameter_m)
    ratio = dy / expected
    slack = lim.slack_px / expected
    dx = np.abs(b[None, :, 0] - r[:, 0:1])
    ok = (
        (narrow + lim.slack_px >= lim.width_ratio_min * w)
        & (dy > 0)
        & (ratio >= lim.spacing_lo - slack)
        & (ratio <= lim.spacing_hi + slack)
        & (dx <= lim.max_dx * w + lim.slack_px)
        & _band_shaped(r, lim)[:, None]
        & _band_shaped(b, lim)[None, :]
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        score = np.abs(np.log(ratio)) + dx / w + np.abs(np.log(rw / bw))
    return np.where(ok, score, np.inf)


def pair_bands(
    red_boxes: np.ndarray,
    blue_boxes: np.ndarray,
    geometry: LandmarkGeometry,
    limits: PairingLimits = DEFAULT_LIMITS,
    max_pairs: int = 16,
) -> List[Tuple[int, int]]:
    """Greedy best-first pairing: each box joins at most one landmark.

    Returns ``(red index, blue index)`` pairs, best-fitting first; the boxes left
    over are dropped.
    """
    if len(red_boxes) == 0 or len(blue_boxes) == 0:
        return []
    scores = pair_scores(red_boxes, blue_boxes, geometry, limits)
    ri, bi = np.nonzero(np.isfinite(scores))
    used_r, used_b, pairs = set(), set(), []
    for _s, i, j in sorted(zip(scores[ri, bi].tolist(), ri.tolist(), bi.tolist())):
        if i in used_r or j in used_b:
            continue
        used_r.add(i)
        used_b.add(j)
        pairs.append((i, j))
        if len(pairs) >= max_pairs:
            break
    return pairs
