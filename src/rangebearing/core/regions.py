"""Band regions for the structure search: each colour's regions of a class mask, at most ``MAX_REGIONS``.

A frame full of specks (a noisy floor, a carpet laced with red) can make hundreds of regions; the
search examines at most ``MAX_REGIONS`` of each colour, and :func:`band_regions` decides which:
those that could pair with the other colour first, then the largest (see :mod:`.structure`).
"""

from __future__ import annotations

from typing import Sequence, Tuple

import cv2
import numpy as np

MAX_REGIONS = 128  # largest regions of each colour considered (bounds the cost of a frame full of specks)


def region_stats(mask: np.ndarray, min_area: int, cap: bool = True) -> np.ndarray:
    """``(0, x, y, w, h, box area)`` rows of the external regions of a 0/255 mask whose box holds at
    least ``min_area`` pixels, the ``MAX_REGIONS`` largest (all of them with ``cap=False``;
    contours: far cheaper than labelling)."""
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    if not contours:
        return np.zeros((0, 6), np.int64)
    st = np.array([cv2.boundingRect(c) for c in contours], np.int64).reshape(-1, 4)
    area = st[:, 2] * st[:, 3]
    keep = area >= min_area
    st, area = st[keep], area[keep]
    if cap and len(st) > MAX_REGIONS:
        top = np.argsort(-area, kind="stable")[:MAX_REGIONS]
        st, area = st[top], area[top]
    return np.column_stack((np.zeros(len(st), np.int64), st, area))


def band_regions(red: np.ndarray, blue: np.ndarray, min_area: int) -> Tuple[np.ndarray, np.ndarray]:
    """The red and the blue :func:`region_stats` of two masks, at most ``MAX_REGIONS`` of each.

    When a colour has more regions than that (a noisy floor or carpet laced with red), the
    regions with some of the other colour where a partner could be (:func:`partnered`) are
    kept first, largest first, then the largest of the rest: a far landmark's small band region
    must not lose its place to big blotches of floor with no blue under them. With both colours
    under the cap this is :func:`region_stats` of each.
    """
    reds, blues = region_stats(red, min_area, cap=False), region_stats(blue, min_area, cap=False)
    if len(reds) > MAX_REGIONS:
        reds = _capped(reds, partnered(reds, blue, below=True))
    if len(blues) > MAX_REGIONS:
        blues = _capped(blues, partnered(blues, red, below=False))
    return reds, blues


def partnered(regions: np.ndarray, other: np.ndarray, below: bool) -> np.ndarray:
    """Which regions have a pixel of the ``other`` colour's 0/255 mask where :func:`region_pairs`
    could find their partner: in their columns, from their top down to a white body's reach
    (4 widths + 3) below their bottom (``below``: a red region's blue), or up to that far
    above their top, down to their bottom (a blue region's red). One integral image; a
    superset of the regions that pair, so none that pairs is put behind one that cannot."""
    total = cv2.integral(other, sdepth=cv2.CV_32S)
    h, w = other.shape
    x0, y0, rw, rh = (regions[:, k] for k in (1, 2, 3, 4))
    reach = 4 * rw + 3
    top = y0 if below else y0 - reach - rw
    bottom = y0 + rh + reach if below else y0 + rh
    r0, r1 = np.clip(top, 0, h), np.clip(bottom, 0, h)
    c0, c1 = np.clip(x0, 0, w), np.clip(x0 + rw, 0, w)
    inside = total[r1, c1] - total[r0, c1] - total[r1, c0] + total[r0, c0]
    return inside > 0


def _capped(st: np.ndarray, first: np.ndarray) -> np.ndarray:
    return st[np.lexsort((-st[:, 5], ~first))[:MAX_REGIONS]]  # partnered first, then by box area


APART_MARGIN = 0.25  # a region within a found landmark's box grown by this share of its size (and 2 px) is its


def outside(regions: np.ndarray, boxes: Sequence[Tuple[int, int, int, int]], scale: int) -> np.ndarray:
    """The :func:`region_stats` rows (mask pixels) that do not lie within any ``(x0, y0, x1, y1)`` box
    (full-resolution pixels) grown by ``APART_MARGIN`` of its size and 2 mask pixels: the regions
    of a landmark found already (its bands and their rims under lower colour floors) are its own."""
    if not len(regions) or not boxes:
        return regions
    b = np.asarray(boxes, np.float64) / scale
    mx = np.maximum(2.0, APART_MARGIN * (b[:, 2] - b[:, 0]))
    my = np.maximum(2.0, APART_MARGIN * (b[:, 3] - b[:, 1]))
    rx0, ry0 = regions[:, 1, None], regions[:, 2, None]
    rx1, ry1 = rx0 + regions[:, 3, None], ry0 + regions[:, 4, None]
    inside = (rx0 >= b[:, 0] - mx) & (ry0 >= b[:, 1] - my) & (rx1 <= b[:, 2] + mx) & (ry1 <= b[:, 3] + my)
    return regions[~inside.any(axis=1)]
