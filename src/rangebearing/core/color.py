"""Colour stages: white balance, HSV conversion and the red/blue hue thresholds.

All functions take and return numpy arrays and do no I/O. Hue follows OpenCV's
8-bit convention (0–179, i.e. degrees / 2); saturation and value are 0–255.
"""

from __future__ import annotations

import functools
from typing import Sequence, Tuple

import cv2
import numpy as np

Gains = Tuple[float, float, float]
HueRanges = Sequence[Tuple[int, int]]

UNIT_GAINS: Gains = (1.0, 1.0, 1.0)
CHROMA_FLOOR = 0.15  # share of a band's chroma below which a pixel does not count


def grey_world_gains(bgr: np.ndarray, limit: float = 2.0) -> Gains:
    """Channel gains that make the frame's mean colour neutral (grey-world).

    Parameters
    ----------
    bgr : (H, W, 3) uint8 array
        Any image in BGR order; a downscaled frame is enough.
    limit : float
        Gains are clipped to ``[1/limit, limit]`` so a frame filled with one
        colour cannot swing the balance arbitrarily.

    Returns
    -------
    (g_b, g_g, g_r) : tuple of float
        Multiply channel c by ``g_c``; a neutral frame gives ``(1, 1, 1)``.
    """
    b, g, r, _ = cv2.mean(bgr)
    grey = (b + g + r) / 3.0
    if grey <= 1.0:
        return UNIT_GAINS
    return tuple(float(np.clip(grey / max(c, 1e-3), 1.0 / limit, limit)) for c in (b, g, r))  # type: ignore[return-value]


def apply_gains(bgr: np.ndarray, gains: Gains) -> np.ndarray:
    """Scale each channel by its gain, saturating at 255 (uint8 in, uint8 out)."""
    if gains == UNIT_GAINS:
        return bgr
    return cv2.multiply(bgr, (gains[0], gains[1], gains[2], 0.0))


def to_hsv(bgr: np.ndarray) -> np.ndarray:
    """BGR uint8 → HSV uint8 with OpenCV's 0–179 hue."""
    return cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)


def hue_mask(hsv: np.ndarray, hue_ranges: HueRanges, s_min: int, v_min: int) -> np.ndarray:
    """Binary mask (0/255 uint8) of pixels inside any hue range with S ≥ s_min and V ≥ v_min.

    Red wraps around hue 0, so it is given as two ranges, e.g. ``[(0, 10), (165, 179)]``.
    """
    lo, hi = hue_ranges[0]
    mask = cv2.inRange(hsv, (lo, s_min, v_min), (hi, 255, 255))
    for lo, hi in hue_ranges[1:]:
        mask = cv2.bitwise_or(mask, cv2.inRange(hsv, (lo, s_min, v_min), (hi, 255, 255)))
    return mask


@functools.lru_cache(maxsize=16)
def _ramp_table(lo: int, width: int) -> np.ndarray:
    """float32 lookup table: 0 at ``lo`` rising linearly to 1 at ``lo + width``."""
    return np.clip((np.arange(256, dtype=np.float32) - lo) / float(width), 0.0, 1.0).reshape(256, 1)


def soft_weights(
    hsv: np.ndarray, hue_ranges: HueRanges, s_min: int, v_min: int, ramp: int = 40
) -> Tuple[np.ndarray, np.ndarray]:
    """Per-pixel band membership in [0, 1] for sub-pixel moments: ``(w_x, w_y)``, float32.

    Both are zero outside the hue ranges (and for pixels darker than 10).

    ``w_x`` weighs by saturation on a linear ramp from ``s_min - ramp`` (0) to
    ``s_min + ramp`` (1). Saturation does not depend on brightness, so the
    shading across the cylinder does not pull the *horizontal* centroid.

    ``w_y`` weighs by chroma (max − min channel, i.e. S·V) relative to the
    band's own mean chroma, above a floor. Chroma is linear in the share of a
    pixel the band covers whether the neighbour is the white body or the dark
    robot below, so the *vertical* centroid, and with it L, is unbiased;
    saturation would count a blue/black edge pixel as fully blue.
    """
    gate = hue_mask(hsv, hue_ranges, 1, min(v_min, 10))
    s, v = hsv[:, :, 1], hsv[:, :, 2]
    loose_s = max(0, s_min - ramp)
    w_x = cv2.LUT(s, _ramp_table(loose_s, 2 * ramp))
    w_x[gate == 0] = 0.0
    chroma = cv2.multiply(s, v, dtype=cv2.CV_32F)
    core = cv2.bitwise_and(gate, cv2.compare(s, s_min, cv2.CMP_GE))
    ref = cv2.mean(chroma, mask=core)[0]
    if ref <= 0.0:
        return w_x, w_x
    # An affine ramp with a floor: faint blends count the same on either side of
    # the band, and the chroma noise of neutral pixels counts not at all.
    floor = CHROMA_FLOOR * ref
    w_y = np.clip((chroma - floor) * (1.0 / (ref - floor)), 0.0, 1.0)
    w_y[gate == 0] = 0.0
    return w_x, w_y
