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
    """Scale each channel by its gain, saturating at 255 (uint8 in, uint8 out).

    Gains within 2 % of one are skipped: they move no threshold decision that matters.
    """
    if all(abs(g - 1.0) <= 0.02 for g in gains):
        return bgr
    return cv2.transform(bgr, np.diag(np.asarray(gains, np.float64)))


def to_hsv(bgr: np.ndarray) -> np.ndarray:
    """BGR uint8 → HSV uint8 with OpenCV's 0–179 hue."""
    return cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)


@functools.lru_cache(maxsize=16)
def hue_table(hue_ranges: Tuple[Tuple[int, int], ...]) -> np.ndarray:
    """uint8 lookup table for ``cv2.LUT``: 255 for hues inside any range, else 0."""
    table = np.zeros((256, 1), np.uint8)
    for lo, hi in hue_ranges:
        table[lo : hi + 1] = 255
    return table


def hue_in(h: np.ndarray, hue_ranges: HueRanges) -> np.ndarray:
    """0/255 mask of hue values inside any of the ranges (one table lookup)."""
    return cv2.LUT(h, hue_table(tuple(map(tuple, hue_ranges))))


def sv_gate(s: np.ndarray, v: np.ndarray, s_min: int, v_min: int) -> np.ndarray:
    """0/255 mask of S ≥ s_min and V ≥ v_min."""
    _, s_ok = cv2.threshold(s, s_min - 1, 255, cv2.THRESH_BINARY)
    _, v_ok = cv2.threshold(v, v_min - 1, 255, cv2.THRESH_BINARY)
    return cv2.bitwise_and(s_ok, v_ok)


def hue_mask(hsv: np.ndarray, hue_ranges: HueRanges, s_min: int, v_min: int) -> np.ndarray:
    """Binary mask (0/255 uint8) of pixels inside any hue range with S ≥ s_min and V ≥ v_min.

    Red wraps around hue 0, so it is given as two ranges, e.g. ``[(0, 10), (165, 179)]``.
    """
    h, s, v = cv2.split(hsv)
    return cv2.bitwise_and(hue_in(h, hue_ranges), sv_gate(s, v, s_min, v_min))


def class_masks(
    hsv: np.ndarray, red_hue: HueRanges, blue_hue: HueRanges, s_min: int, v_min: int
) -> Tuple[np.ndarray, np.ndarray]:
    """The red and the blue :func:`hue_mask` of one image, sharing the channel split and S/V gate."""
    h, s, v = cv2.split(hsv)
    sv = sv_gate(s, v, s_min, v_min)
    return cv2.bitwise_and(hue_in(h, red_hue), sv), cv2.bitwise_and(hue_in(h, blue_hue), sv)


@functools.lru_cache(maxsize=16)
def ramp_table(lo: int, width: int) -> np.ndarray:
    """uint8 lookup table for ``cv2.LUT``: 0 up to ``lo``, rising linearly to 255 at ``lo + width``."""
    ramp = np.clip((np.arange(256, dtype=np.float64) - lo) / float(width), 0.0, 1.0)
    return np.round(255.0 * ramp).astype(np.uint8).reshape(256, 1)
