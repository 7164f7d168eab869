"""Band detection in a whole frame: the fast path and the paper's path.

Fast path (default)::

    downscale (area) → grey-world balance → HSV → red/blue hue thresholds
    → median (majority) filter of the masks, sized to keep the farthest band
    → connected regions → pairing → sub-pixel moments on the *unfiltered*
      full-resolution pixels inside each paired band

The filter decides *where* the bands are; the moments of the original pixels
decide *exactly where*: a median over the colour image rounds the band corners
and moves the centroids, which costs range accuracy.

Paper path: median filter over the whole colour frame, HSV, thresholds, and
the moments of the whole red and blue masks — one landmark at most.

Between full scans, :mod:`rangebearing.core.tracking` measures known landmarks
in place instead.
"""

from __future__ import annotations

from typing import List, Optional, Tuple

import cv2
import numpy as np

from .._compat import frozen
from .blobs import find_boxes, mask_centroid
from .color import Gains, apply_gains, class_masks, hue_mask, to_hsv
from .denoise import majority_filter, median_filter
from .pairing import PairingLimits, pair_bands
from .params import DetectionParams
from .refine import Pyramid, half_or_area, measure_bands
from .types import XY, BBox, union


@frozen
class BandCentroids:
    """One landmark's two bands: sub-pixel centroids, boxes and weights (full-resolution pixels)."""

    red_xy_px: XY
    blue_xy_px: XY
    red_bbox_px: BBox
    blue_bbox_px: BBox
    red_mass_px: float
    blue_mass_px: float
    red_chroma: float
    blue_chroma: float

    @property
    def width_px(self) -> float:
        return 0.5 * (self.red_bbox_px[2] + self.blue_bbox_px[2])

    @property
    def bbox_px(self) -> BBox:
        return union(self.red_bbox_px, self.blue_bbox_px)


def downscale(bgr: np.ndarray, s: int) -> np.ndarray:
    """Area-average the frame by ``s`` (trimming to a multiple of ``s``); ``s = 1`` returns it."""
    if s == 1:
        return bgr
    h, w = bgr.shape[:2]
    return cv2.resize(bgr[: h // s * s, : w // s * s], (w // s, h // s), interpolation=half_or_area(s))


def region_masks(small: np.ndarray, cfg: DetectionParams, gains: Gains, ksize: int) -> Tuple[np.ndarray, np.ndarray]:
    """Filtered red and blue masks of a downscaled frame: balance, HSV, thresholds, majority filter."""
    hsv = to_hsv(apply_gains(small, gains))
    red, blue = class_masks(hsv, cfg.red_hue, cfg.blue_hue, cfg.s_min, cfg.v_min)
    return majority_filter(red, ksize), majority_filter(blue, ksize)


def find_pairs(
    small: np.ndarray, cfg: DetectionParams, gains: Gains, ksize: int, limits: PairingLimits, geometry
) -> Tuple[np.ndarray, np.ndarray]:
    """Candidate landmarks in a frame downscaled by ``cfg.downscale``.

    Returns the red and the blue band boxes of each candidate, (K, 4) arrays
    in full-resolution pixels, row k of one paired with row k of the other.
    """
    red, blue = region_masks(small, cfg, gains, ksize)
    min_area = cfg.min_band_px * cfg.min_band_px
    reds = find_boxes(red, cfg.downscale, min_area)
    blues = find_boxes(blue, cfg.downscale, min_area)
    pairs = pair_bands(reds, blues, geometry, limits, cfg.max_landmarks)
    idx = np.array(pairs, np.int64).reshape(-1, 2)
    return reds[idx[:, 0]], blues[idx[:, 1]]


def refine(
    bgr: np.ndarray,
    red_boxes: np.ndarray,
    blue_boxes: np.ndarray,
    cfg: DetectionParams,
    gains: Gains,
    pyramid: Optional[Pyramid] = None,
) -> List[BandCentroids]:
    """Sub-pixel centroids of every candidate, all bands in one batch; candidates whose band vanished are dropped.

    Row k of ``red_boxes`` and of ``blue_boxes`` (full-resolution x, y, w, h)
    belong to candidate k. Each band is measured inside its box grown by
    ``downscale + 1`` px, which covers the downscaling and the filter's erosion.
    """
    m = cfg.downscale + 1
    reds, blues = [tuple(b) for b in red_boxes.tolist()], [tuple(b) for b in blue_boxes.tolist()]
    boxes = [b for pair in zip(reds, blues) for b in pair]
    fixes = measure_bands(bgr, boxes, [True, False] * len(reds), [(m, m)] * len(boxes), cfg, gains, pyramid)
    found = []
    for rb, bb, red, blue in zip(reds, blues, fixes[0::2], fixes[1::2]):
        if red is not None and blue is not None:
            found.append(
                BandCentroids(red.xy_px, blue.xy_px, rb, bb, red.mass_px, blue.mass_px, red.chroma_ref, blue.chroma_ref)
            )
    return found


def detect_paper(bgr: np.ndarray, cfg: DetectionParams) -> List[BandCentroids]:
    """The paper's pipeline as published: median over the colour frame, HSV, whole-mask moments.

    Finds at most one landmark: the centroid of *all* red pixels and of *all*
    blue pixels, so a second landmark or any red/blue object corrupts it.
    """
    hsv = to_hsv(median_filter(bgr, cfg.median_ksize))
    red = mask_centroid(hue_mask(hsv, cfg.red_hue, cfg.s_min, cfg.v_min))
    blue = mask_centroid(hue_mask(hsv, cfg.blue_hue, cfg.s_min, cfg.v_min))
    if red is None or blue is None or blue[1] <= red[1]:
        return []
    side = float(np.sqrt(red[2]))  # the paper has no band boxes: squares of the bands' areas
    boxes = [(int(c[0] - side / 2), int(c[1] - side / 4), int(side), int(side / 2)) for c in (red, blue)]
    return [BandCentroids((red[0], red[1]), (blue[0], blue[1]), boxes[0], boxes[1], red[2], blue[2], 0.0, 0.0)]
