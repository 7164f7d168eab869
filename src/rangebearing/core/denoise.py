"""Noise suppression: the paper's median filter and its cheap binary equivalent."""

from __future__ import annotations

import math
from typing import Sequence, Tuple

import cv2
import numpy as np

Box = Tuple[int, int, int, int]  # x0, y0, x1, y1 in full-resolution pixels


def median_filter(image: np.ndarray, ksize: int) -> np.ndarray:
    """The paper's denoising stage: an OpenCV median filter of odd size ``ksize``.

    Works on uint8 images of 1 or 3 channels; the paper applies size 15 to the
    colour frame.
    """
    if ksize <= 1:
        return image
    return cv2.medianBlur(image, ksize)


def majority_filter(mask: np.ndarray, ksize: int) -> np.ndarray:
    """Median filter of a binary 0/255 mask, computed as a box-sum majority vote.

    For a binary image the median of a k×k window is 255 exactly when more
    than half of the window is set, so a separable box filter and a threshold
    give the same answer as ``cv2.medianBlur`` at a fraction of the cost
    (borders are replicated rather than reflected).
    """
    if ksize <= 1:
        return mask
    mean = cv2.blur(mask, (ksize, ksize), borderType=cv2.BORDER_REPLICATE)
    _, out = cv2.threshold(mean, 127, 255, cv2.THRESH_BINARY)
    return out


def band_preserving_ksize(ksize: int, band_px: float) -> int:
    """The largest odd filter size ≤ ``ksize`` that keeps a band ``band_px`` tall.

    A majority (median) window of size k keeps a long horizontal strip of
    height h only when h·k > k²/2, i.e. k < 2h; beyond that the filter erases
    the band. The paper's size 15 erases the 15 mm bands beyond about 1.2 m
    at 640×480, so the fast pipeline scales the filter to the smallest band it
    must still see.
    """
    limit = max(1, math.floor(2.0 * band_px - 1.0))
    k = min(ksize, limit)
    return k if k % 2 == 1 else k - 1


def regrow(filtered: np.ndarray, raw: np.ndarray, ksize: int) -> np.ndarray:
    """Give back to a majority-filtered mask the pixels of ``raw`` the filter ate at its regions' rims.

    A k×k majority vote erases a region's corners and the ends of a thin strip:
    a 2-pixel band (a landmark at 2 m, half resolution, ``k = 3``) loses a column
    at each end, a third of its width, and reads as a partly hidden landmark.
    The set pixels of ``raw`` within the filter's reach (a k×k neighbourhood) of
    a surviving pixel come back; isolated specks, which the filter removed whole,
    stay removed. Both masks are 0/255 uint8 of one shape.
    """
    if ksize <= 1:
        return filtered
    near = cv2.dilate(filtered, np.ones((ksize, ksize), np.uint8))
    return cv2.bitwise_or(filtered, cv2.bitwise_and(near, raw))


def band_masks(red: np.ndarray, blue: np.ndarray, ksize: int) -> tuple:
    """The red and blue class masks denoised for the region search: majority filter, then :func:`regrow`."""
    return (regrow(majority_filter(red, ksize), red, ksize), regrow(majority_filter(blue, ksize), blue, ksize))


def blanked(mask: np.ndarray, boxes: Sequence[Box], scale: int) -> np.ndarray:
    """``mask`` (0/255, downscaled by ``scale``) with every ``(x0, y0, x1, y1)`` box (full-resolution
    pixels) cleared, grown by one mask pixel; ``mask`` itself when there is none (else a copy)."""
    if not boxes:
        return mask
    out = mask.copy()
    for x0, y0, x1, y1 in boxes:  # floor the start, ceil the end, one pixel more each way
        r0, r1 = max(0, y0 // scale - 1), max(0, -(-y1 // scale) + 1)
        out[r0:r1, max(0, x0 // scale - 1) : max(0, -(-x1 // scale) + 1)] = 0
    return out


def both_outside(red: np.ndarray, blue: np.ndarray, boxes: Sequence[Box], scale: int) -> bool:
    """Whether both masks (0/255, downscaled by ``scale``) have a set pixel outside every box
    (:func:`blanked`): only then can a landmark stand wholly apart from those boxes."""
    return bool(cv2.countNonZero(blanked(red, boxes, scale))) and bool(cv2.countNonZero(blanked(blue, boxes, scale)))


def _mask_rects(boxes: Sequence[Box], scale: int) -> np.ndarray:
    """(N, 4) ``r0, r1, c0, c1`` mask rows and columns ``[r0, r1) × [c0, c1)`` that :func:`blanked` clears."""
    return np.asarray([(max(0, y0 // scale - 1), max(0, -(-y1 // scale) + 1),
                        max(0, x0 // scale - 1), max(0, -(-x1 // scale) + 1)) for x0, y0, x1, y1 in boxes], np.int64)


def none_apart_filtered(red: np.ndarray, blue: np.ndarray, boxes: Sequence[Box], scale: int, ksize: int) -> bool:
    """Whether :func:`band_masks` of the raw class masks ``red``, ``blue`` would certainly fail
    :func:`both_outside` for ``boxes``: judged on the raw masks, without filtering them.

    :func:`regrow` adds only raw pixels, and a majority window centred outside one
    cleared rectangle holds at most ``k·(k//2)`` pixels of it (fewer than half, also with
    the replicated border): so when a raw mask has nothing outside the rectangles, neither
    has its filtered mask, provided no window can reach two rectangles (their ``k//2``
    neighbourhoods are disjoint; else ``False``: filter and look).
    """
    half = ksize // 2 if ksize > 1 else 0
    if len(boxes) > 1:
        r = _mask_rects(boxes, scale)
        i, j = np.triu_indices(len(r), 1)
        near = ((r[i, 0] < r[j, 1] + 2 * half) & (r[j, 0] < r[i, 1] + 2 * half)
                & (r[i, 2] < r[j, 3] + 2 * half) & (r[j, 2] < r[i, 3] + 2 * half))
        if near.any():
            return False
    return not both_outside(red, blue, boxes, scale)
