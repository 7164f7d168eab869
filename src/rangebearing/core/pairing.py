"""Pair red bands with the blue band below them; reject everything that does not fit.

A landmark seen from the side is a cylinder of diameter D with band centres a
vertical distance S apart, so in the image the band centroids are about
``w·S/D`` pixels apart (w the band's width in pixels), one directly above the
other, with bands of similar width. Red boxes, blue posters, tinted floors and
misaligned red/blue pairs fail one of these tests.
"""

from __future__ import annotations

import math
from typing import List, Sequence

from .._compat import frozen
from .types import BandPair, Blob, LandmarkGeometry


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


def pair_score(red: Blob, blue: Blob, geometry: LandmarkGeometry, lim: PairingLimits) -> float:
    """How badly ``red`` over ``blue`` deviates from a landmark; ``inf`` if it cannot be one."""
    w = max(red.width_px, blue.width_px, 1)
    if min(red.width_px, blue.width_px) + lim.slack_px < lim.width_ratio_min * w:
        return math.inf
    dy = blue.cy_px - red.cy_px
    if dy <= 0:
        return math.inf
    expected = w * geometry.band_spacing_m / geometry.diameter_m
    ratio = dy / expected
    slack = lim.slack_px / expected
    if not lim.spacing_lo - slack <= ratio <= lim.spacing_hi + slack:
        return math.inf
    dx = abs(blue.cx_px - red.cx_px)
    if dx > lim.max_dx * w + lim.slack_px:
        return math.inf
    for b in (red, blue):
        aspect_slack = lim.slack_px / b.width_px if b.width_px else 0.0
        aspect = b.height_px / max(b.width_px, 1)
        if not lim.band_aspect_lo - aspect_slack <= aspect <= lim.band_aspect_hi + aspect_slack:
            return math.inf
    return abs(math.log(ratio)) + dx / w + abs(math.log(max(red.width_px, 1) / max(blue.width_px, 1)))


def pair_bands(
    reds: Sequence[Blob],
    blues: Sequence[Blob],
    geometry: LandmarkGeometry,
    limits: PairingLimits = DEFAULT_LIMITS,
    max_pairs: int = 16,
) -> List[BandPair]:
    """Greedy best-first pairing: each blob joins at most one landmark.

    Returns the accepted pairs, best-fitting first; unpaired blobs are dropped.
    """
    candidates = []
    for i, r in enumerate(reds):
        for j, b in enumerate(blues):
            s = pair_score(r, b, geometry, limits)
            if s < math.inf:
                candidates.append((s, i, j))
    candidates.sort()
    used_r, used_b, pairs = set(), set(), []
    for _s, i, j in candidates:
        if i in used_r or j in used_b:
            continue
        used_r.add(i)
        used_b.add(j)
        pairs.append(BandPair(red=reds[i], blue=blues[j]))
        if len(pairs) >= max_pairs:
            break
    return pairs
