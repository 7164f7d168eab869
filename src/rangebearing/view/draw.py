"""What the view page shows, made from one frame and its result: the overlay, the masks, the JSON state.

These run on the view's encoder thread, never in the capture loop.
"""

from __future__ import annotations

import math
from typing import Any, Dict, Optional, Tuple

import cv2
import numpy as np

from ..core.color import UNIT_GAINS, apply_gains, class_masks, grey_world_gains, to_hsv
from ..core.types import FrameResult, Landmark

GREEN, RED, BLUE, GREY, YELLOW = (60, 220, 60), (40, 40, 255), (255, 120, 40), (170, 170, 170), (0, 220, 255)
FONT = cv2.FONT_HERSHEY_SIMPLEX


def _text(img: np.ndarray, label: str, org: tuple, colour: tuple, scale: float = 0.42) -> None:
    cv2.putText(img, label, org, FONT, scale, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(img, label, org, FONT, scale, colour, 1, cv2.LINE_AA)


def label(lm: Landmark) -> Tuple[str, str]:
    """Two lines: ``#3 0.412 m +-4 mm`` and ``+12.3 deg +-0.05`` (the track id and σ when known).

    OpenCV's Hershey fonts have no ``±`` or ``°``.
    """
    tid = f"#{lm.track_id} " if lm.track_id >= 0 else ""
    rng = f"{tid}{lm.range_m:.3f} m"
    if lm.range_sigma_m > 0:
        rng += f" +-{lm.range_sigma_m * 1000:.0f} mm"
    brg = f"{math.degrees(lm.bearing_rad):+.1f} deg"
    if lm.bearing_sigma_rad > 0:
        brg += f" +-{math.degrees(lm.bearing_sigma_rad):.2f}"
    return rng, brg


def overlay(frame_bgr: np.ndarray, result: FrameResult, band_ratio: float = 15.0 / 55.0) -> np.ndarray:
    """A copy of the frame with each landmark's bands, centroids, range, bearing, σ and track id drawn.

    The band boxes are drawn around each centroid, as wide as the landmark and
    as tall as a band (``band_ratio`` = band height / band spacing, times the
    centroid distance).
    Landmarks outside the calibrated envelope are grey, partly hidden ones (``visible`` < 0.9) yellow.
    """
    out = frame_bgr.copy()
    for lm in result.landmarks:
        x, y, w, h = lm.bbox_px
        colour = GREY if not lm.in_envelope else (YELLOW if lm.visible < 0.9 else GREEN)
        cv2.rectangle(out, (x, y), (x + w, y + h), colour, 1)
        half_w, half_h = lm.width_px / 2.0, max(1.0, lm.l_px * band_ratio / 2.0)
        for (cx, cy), c in ((lm.red_xy_px, RED), (lm.blue_xy_px, BLUE)):
            p0 = (round(cx - half_w), round(cy - half_h))
            p1 = (round(cx + half_w), round(cy + half_h))
            cv2.rectangle(out, p0, p1, c, 1)
            cv2.drawMarker(out, (round(cx), round(cy)), c, cv2.MARKER_CROSS, 9, 1)
        (rx, ry), (bx, by) = lm.red_xy_px, lm.blue_xy_px
        cv2.line(out, (round(rx), round(ry)), (round(bx), round(by)), colour, 1)
        top, bottom = label(lm)
        ty = y - 19 if y > 30 else y + h + 14
        _text(out, top, (x, ty), colour)
        _text(out, bottom, (x, ty + 14), colour)
    return out


def masks(frame_bgr: np.ndarray, detection: Any) -> np.ndarray:
    """The red and blue threshold masks as the detector sees them, over a dimmed copy of its input.

    Made exactly as the fast path makes them (area downscale, grey-world
    balance when configured, HSV, the hue ranges and the S/V minimums), at the
    detector's resolution; red-mask pixels are drawn red, blue-mask pixels blue.
    """
    s = int(detection.downscale)
    h, w = frame_bgr.shape[:2]
    small = frame_bgr if s == 1 else cv2.resize(frame_bgr, (w // s, h // s), interpolation=cv2.INTER_AREA)
    gains = grey_world_gains(small) if detection.white_balance == "grey_world" else UNIT_GAINS
    red, blue = class_masks(
        to_hsv(apply_gains(small, gains)), detection.red_hue, detection.blue_hue, detection.s_min, detection.v_min
    )
    out = (small // 4).astype(np.uint8)
    out[red > 0] = RED
    out[blue > 0] = BLUE
    return out


def encode_jpeg(img: np.ndarray, quality: int = 80) -> bytes:
    ok, buf = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, quality])
    if not ok:  # pragma: no cover - OpenCV encodes any uint8 BGR image
        raise ValueError("JPEG encoding failed")
    return buf.tobytes()


def _finite(v: Optional[float]) -> Optional[float]:
    return None if v is None or not math.isfinite(v) else float(v)


def landmark_json(lm: Landmark) -> Dict[str, Any]:
    """One landmark for the page: the reading, its σ, and its place on the floor (x forward, y left)."""
    return {
        "range_m": lm.range_m,
        "bearing_rad": lm.bearing_rad,
        "range_sigma_m": lm.range_sigma_m,
        "bearing_sigma_rad": lm.bearing_sigma_rad,
        "visible": lm.visible,
        "track_id": lm.track_id,
        "in_envelope": lm.in_envelope,
        "range_rate_mps": _finite(lm.range_rate_mps),
        "bearing_rate_radps": _finite(lm.bearing_rate_radps),
        "x_m": lm.range_m * math.cos(lm.bearing_rad),
        "y_m": lm.range_m * math.sin(lm.bearing_rad),
        "red_xy_px": list(lm.red_xy_px),
        "blue_xy_px": list(lm.blue_xy_px),
        "bbox_px": list(lm.bbox_px),
        "l_px": lm.l_px,
    }
