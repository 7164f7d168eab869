"""Draw what the pipeline found onto a copy of the frame (for ``replay --annotate``)."""

from __future__ import annotations

import math
from typing import List, Tuple

import cv2
import numpy as np

from ..core.types import FrameResult, Landmark, LandmarkGeometry

GREEN, RED, BLUE, GREY, YELLOW = (60, 220, 60), (40, 40, 255), (255, 120, 40), (170, 170, 170), (0, 230, 255)
SPACING_M = LandmarkGeometry().band_spacing_m


def _text(out: np.ndarray, text: str, org: Tuple[int, int], colour: Tuple[int, int, int]) -> None:
    cv2.putText(out, text, org, cv2.FONT_HERSHEY_SIMPLEX, 0.4, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(out, text, org, cv2.FONT_HERSHEY_SIMPLEX, 0.4, colour, 1, cv2.LINE_AA)


def error_bars(lm: Landmark) -> Tuple[float, float]:
    """Half-lengths in pixels of the 1σ error bars: bearing (horizontal) and range (vertical, at each band).

    The bearing bar is ``σ_θ`` seen at the landmark's distance (``L·r/spacing``
    pixels per radian); the range bar is how far each centroid would move for
    a 1σ range change (``L`` scales as 1/range, so ``L·σ_r/r`` split over both
    ends). Both are measured in the image, where the reading came from.
    """
    px_per_rad = lm.l_px * lm.range_m / SPACING_M
    bearing_px = lm.bearing_sigma_rad * px_per_rad
    range_px = 0.5 * lm.l_px * lm.range_sigma_m / lm.range_m if lm.range_m > 0 else 0.0
    return bearing_px, range_px


def labels(lm: Landmark) -> List[str]:
    """The text drawn above a landmark: id, range and bearing with their sigmas; the rates below."""
    head = f"id {lm.track_id} " if lm.track_id >= 0 else ""
    lines = [f"{head}{lm.range_m:.3f}+-{lm.range_sigma_m:.3f} m {math.degrees(lm.bearing_rad):+.1f}"
             f"+-{math.degrees(lm.bearing_sigma_rad):.1f} deg"]  # Hershey fonts are ASCII
    if lm.range_rate_mps is not None and lm.bearing_rate_radps is not None:
        lines.append(f"{lm.range_rate_mps:+.2f} m/s {math.degrees(lm.bearing_rate_radps):+.0f} deg/s")
    if lm.visible < 0.995:
        lines.append(f"{100 * lm.visible:.0f}% visible")
    return lines


def annotate(frame_bgr: np.ndarray, result: FrameResult) -> np.ndarray:
    """A copy of the frame with each landmark's box, band centroids, 1σ error bars, track id,
    range and bearing drawn on it.

    Landmarks outside the calibrated envelope are drawn in grey; the error
    bars are yellow (see :func:`error_bars`).
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
        hb, hr = (max(1, round(v)) for v in error_bars(lm))
        mx, my = round((rx + bx) / 2), round((ry + by) / 2)
        cv2.line(out, (mx - hb, my), (mx + hb, my), YELLOW, 1)
        for ex in (mx - hb, mx + hb):
            cv2.line(out, (ex, my - 2), (ex, my + 2), YELLOW, 1)
        for cx, cy in ((rx, ry), (bx, by)):
            cv2.line(out, (round(cx) + 6, round(cy) - hr), (round(cx) + 6, round(cy) + hr), YELLOW, 1)
        lines = labels(lm)
        above = y > 12 * len(lines)
        for i, text in enumerate(lines):
            ty = y - 4 - 12 * (len(lines) - 1 - i) if above else y + h + 12 * (i + 1)
            _text(out, text, (x, ty), colour)
    return out
