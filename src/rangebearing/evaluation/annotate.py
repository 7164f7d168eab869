"""Draw what the pipeline found onto a copy of the frame (for ``replay --annotate``)."""

from __future__ import annotations

import math

import cv2
import numpy as np

from ..core.types import FrameResult

GREEN, RED, BLUE, GREY = (60, 220, 60), (40, 40, 255), (255, 120, 40), (170, 170, 170)


def annotate(frame_bgr: np.ndarray, result: FrameResult) -> np.ndarray:
    """A copy of the frame with each landmark's box, band centroids, range and bearing drawn on it.

    Landmarks outside the calibrated envelope are drawn in grey.
    """
    out = frame_bgr.copy()
    for lm in result.landmarks:
        x, y, w, h = lm.bbox_px
        colour = GREEN if lm.in_envelope else GREY
        cv2.rectangle(out, (x, y), (x + w, y + h), colour, 1)
        for (cx, cy), c in ((lm.red_xy_px, RED), (lm.blue_xy_px, BLUE)):
            cv2.drawMarker(out, (round(cx), round(cy)), c, cv2.MARKER_CROSS, 9, 1)
        (rx, ry), (bx, by) = lm.red_xy_px, lm.blue_xy_px
        cv2.line(out, (round(rx), round(ry)), (round(bx), round(by)), colour, 1)
        label = f"{lm.range_m:.3f} m {math.degrees(lm.bearing_rad):+.1f} deg"
        ty = y - 4 if y > 12 else y + h + 12
        cv2.putText(out, label, (x, ty), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (0, 0, 0), 3, cv2.LINE_AA)
        cv2.putText(out, label, (x, ty), cv2.FONT_HERSHEY_SIMPLEX, 0.4, colour, 1, cv2.LINE_AA)
    return out
