"""Connected regions of a binary mask, and weighted image moments."""

from __future__ import annotations

from typing import List, Optional, Tuple

import cv2
import numpy as np

from .types import Blob


def find_blobs(
    mask: np.ndarray,
    scale: float = 1.0,
    offset_px: Tuple[int, int] = (0, 0),
    min_area_px: float = 1.0,
) -> List[Blob]:
    """External connected regions of a 0/255 mask, in full-resolution pixels.

    Parameters
    ----------
    mask : (h, w) uint8 array
        Binary mask, possibly a downscaled one.
    scale : float
        Size of one mask pixel in full-resolution pixels (the downscale factor).
    offset_px : (x, y)
        Full-resolution position of the mask's top-left corner.
    min_area_px : float
        Smallest region kept, in full-resolution pixels.

    Returns
    -------
    list of Blob
        Box centre, box area and bounding box, mapped so that mask pixel
        centre i lands on ``offset + (i + 0.5)·scale − 0.5``. Coarse on
        purpose: they only locate and pair bands; the sub-pixel centroids come
        from :mod:`rangebearing.core.refine`.
    """
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    ox, oy = offset_px
    blobs = []
    s2 = scale * scale
    for c in contours:
        x, y, w, h = cv2.boundingRect(c)
        area = w * h * s2  # the box's area: enough to drop specks and to pair; refinement measures the rest
        if area < min_area_px:
            continue
        blobs.append(
            Blob(
                cx_px=ox + (x + w / 2.0) * scale - 0.5,
                cy_px=oy + (y + h / 2.0) * scale - 0.5,
                area_px=float(area),
                bbox_px=(int(ox + x * scale), int(oy + y * scale), round(w * scale), round(h * scale)),
            )
        )
    return blobs


def mask_centroid(mask: np.ndarray) -> Optional[Tuple[float, float, float]]:
    """The paper's moment centroid of a binary mask: ``(x, y, area_px)`` or ``None``."""
    m = cv2.moments(mask, binaryImage=True)
    if m["m00"] <= 0:
        return None
    return m["m10"] / m["m00"], m["m01"] / m["m00"], m["m00"]
