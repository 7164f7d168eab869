"""Connected regions of a binary mask, and weighted image moments."""

from __future__ import annotations

from typing import Optional, Tuple

import cv2
import numpy as np


def find_boxes(mask: np.ndarray, scale: int = 1, min_area_px: float = 1.0) -> np.ndarray:
    """Bounding boxes of the external connected regions of a 0/255 mask, in full-resolution pixels.

    Parameters
    ----------
    mask : (h, w) uint8 array
        Binary mask, possibly downscaled by ``scale``.
    scale : int
        Size of one mask pixel in full-resolution pixels (the downscale factor).
    min_area_px : float
        Smallest box area kept, in full-resolution pixels.

    Returns
    -------
    (N, 4) int64 array
        ``x, y, width, height`` per region. Coarse on purpose: boxes only locate
        and pair the bands; :mod:`rangebearing.core.refine` measures them.
    """
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    if not contours:
        return np.zeros((0, 4), np.int64)
    boxes = np.array([cv2.boundingRect(c) for c in contours], np.int64) * scale
    return boxes[boxes[:, 2] * boxes[:, 3] >= min_area_px]


def mask_centroid(mask: np.ndarray) -> Optional[Tuple[float, float, float]]:
    """The paper's moment centroid of a binary mask: ``(x, y, area_px)`` or ``None``."""
    m = cv2.moments(mask, binaryImage=True)
    if m["m00"] <= 0:
        return None
    return m["m10"] / m["m00"], m["m01"] / m["m00"], m["m00"]
