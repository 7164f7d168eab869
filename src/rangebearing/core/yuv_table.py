"""Pixel classes of a YUV420 image as tables indexed by a pixel's (U, V) pair, with bounds on its Y.

RGB = a·(Y − y0) + d(U, V): the same ``a·(Y − y0)`` is added to every channel, so
hue and chroma C = max − min depend on U and V alone, and HSV's value
V = a·(Y − y0) + max(d) and saturation S = 255·C / V turn every floor or
ceiling on them into a bound on Y (``V ≥ v_min`` is ``Y ≥ ylo(U, V)``, ``S ≥
s_min`` is ``Y ≤ yhi(U, V)``). :func:`class_table` holds the plain thresholds
(:func:`~rangebearing.core.color.class_masks` without its clipped rules);
:func:`clipped_table` the rules for clipped pixels (V ≥ ``CLIPPED``, before or
after the gains): the wider hues of :func:`~rangebearing.core.color.clipped_hue_tables`
at S ≥ ``CLIPPED_HUE_S_MIN``, and :func:`~rangebearing.core.color.sv_gate`'s
S ≥ s_min/2. A pixel is of a class when either table's interval holds its Y.
"""

from __future__ import annotations

import functools
from typing import Tuple

import cv2
import numpy as np

from .color import CLIPPED, CLIPPED_HUE_S_MIN, clipped_hue_tables, hue_table

# Y'CbCr → R'G'B' (8 bit): R = a·(Y − y0) + rv·(V − 128); G = a·(Y − y0) + gu·(U − 128) + gv·(V − 128);
# B = a·(Y − y0) + bu·(U − 128). SMPTE 170M is BT.601 limited range: libcamera's default for
# video below 1280×720, and what OpenCV's COLOR_BGR2YUV_I420 produces.
COLOUR_SPACES = {
    "smpte170m": (255 / 219, 16.0, 255 / 224 * 1.402, -255 / 224 * 1.772 * 0.114 / 0.587,
                  -255 / 224 * 1.402 * 0.299 / 0.587, 255 / 224 * 1.772),
    "sycc": (1.0, 0.0, 1.402, -1.772 * 0.114 / 0.587, -1.402 * 0.299 / 0.587, 1.772),
    "rec709": (255 / 219, 16.0, 255 / 224 * 1.5748, -255 / 224 * 1.8556 * 0.0722 / 0.7152,
               -255 / 224 * 1.5748 * 0.2126 / 0.7152, 255 / 224 * 1.8556),
}
NONE, RED, BLUE = 0, 1, 2


def _rgb_matrix(colour_space: str) -> Tuple[np.ndarray, np.ndarray]:
    """(3×3 M, 3 offset) with [R, G, B] = M · [Y, U, V] + offset."""
    a, y0, rv, gu, gv, bu = COLOUR_SPACES[colour_space]
    m = np.array([[a, 0.0, rv], [a, gu, gv], [a, bu, 0.0]])
    return m, -m @ np.array([y0, 128.0, 128.0])


@functools.lru_cache(maxsize=4)
def _chroma_planes(colour_space: str) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(256, 256) planes over (U rows, V columns): 8-bit hue, top = max(R, G, B) − a(Y − y0), chroma C."""
    m, _ = _rgb_matrix(colour_space)
    du = (np.arange(256.0) - 128.0)[:, None]  # U down the rows, V along them: the index U << 8 | V
    dv = (np.arange(256.0) - 128.0)[None, :]
    # R, G, B minus a(Y - y0), as planes (built on the daemon's first frame: no (256, 256, 3) stack and
    # axis reductions, ~3x cheaper; the same values)
    r, g, b = (m[k, 1] * du + m[k, 2] * dv for k in range(3))
    bgr = cv2.merge([(p + 256.0).astype(np.float32) for p in (b, g, r)])  # hue does not change with a common offset
    hue = cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)[..., 0]
    hue8 = np.round(hue / 2.0).astype(np.int64) % 180
    top = np.maximum(np.maximum(r, g), b)
    chroma = top - np.minimum(np.minimum(r, g), b)
    for p in (hue8, top, chroma):
        p.setflags(write=False)
    return hue8, top, chroma


def _y_bounds(colour_space: str, v_floor: float, s_floor: float) -> Tuple[np.ndarray, np.ndarray]:
    """Float (256, 256) ylo, yhi: V = a(Y − y0) + top ≥ v_floor − 0.5 and S = 255·C / V ≥ s_floor − 0.5."""
    a, y0 = COLOUR_SPACES[colour_space][:2]
    _, top, chroma = _chroma_planes(colour_space)
    ylo = np.ceil(y0 + (v_floor - 0.5 - top) / a)
    with np.errstate(divide="ignore"):
        vmax = 255.0 * chroma / max(s_floor - 0.5, 1e-6)
    return ylo, np.floor(y0 + (vmax - top) / a)


def _hue_classes(hue8: np.ndarray, chroma: np.ndarray, red_lut: np.ndarray, blue_lut: np.ndarray) -> np.ndarray:
    """uint32 (256, 256) class of each hue under two ``cv2.LUT`` tables (blue wins where both take it)."""
    cls = np.zeros(hue8.shape, np.uint32)
    for label, lut in ((RED, red_lut), (BLUE, blue_lut)):
        cls[(lut[hue8, 0] > 0) & (chroma > 0)] = label
    return cls


@functools.lru_cache(maxsize=8)
def class_table(colour_space: str, red_hue: tuple, blue_hue: tuple, s_min: int, v_min: int) -> np.ndarray:
    """(65536,) uint32 table indexed by ``U << 8 | V``: ylo | yhi << 8 | class << 16.

    A pixel is of ``class`` (RED, BLUE; NONE is 0) when ``ylo ≤ Y ≤ yhi``;
    hue follows OpenCV's 8-bit convention (0–179), S and V are 0–255 and
    rounded as OpenCV rounds them.
    """
    hue8, _, chroma = _chroma_planes(colour_space)
    cls = _hue_classes(hue8, chroma, hue_table(tuple(map(tuple, red_hue))), hue_table(tuple(map(tuple, blue_hue))))
    ylo, yhi = _y_bounds(colour_space, v_min, s_min)
    empty = (ylo > yhi) | (ylo > 255) | (yhi < 0) | (cls == NONE)
    ylo = np.where(empty, 255, np.clip(ylo, 0, 255)).astype(np.uint32)  # 255 ≤ Y ≤ 0: no pixel
    yhi = np.where(empty, 0, np.clip(yhi, 0, 255)).astype(np.uint32)
    return (ylo | (yhi << 8) | (cls << 16)).reshape(-1)


@functools.lru_cache(maxsize=8)
def clipped_table(colour_space: str, red_hue: tuple, blue_hue: tuple, s_min: int) -> np.ndarray:
    """(65536,) uint32 table indexed by ``U << 8 | V``: yclip | yhi << 8 | class << 16 | yclip << 24.

    The clipped pixels' rules of the BGR path. A pixel is clipped after the
    gains when V ≥ ``CLIPPED``: ``Y ≥ yclip``. A clipped pixel is of ``class``
    when ``Y ≤ yhi``: for a hue inside the class's range, S ≥ s_min // 2
    (:func:`~rangebearing.core.color.sv_gate`); for a hue only the clipped
    ranges take (:func:`~rangebearing.core.color.clipped_hue_tables`),
    S ≥ max(``CLIPPED_HUE_S_MIN``, s_min // 2) (:func:`~rangebearing.core.color.clip_of`).
    A pixel clipped *before* the gains is clipped whatever its Y: it needs only
    ``Y ≤ yhi``, and the top byte (yclip of the unbalanced pixel's own (U, V))
    is what tells it: unbalanced ``Y ≥ yclip``.
    """
    red_key, blue_key = tuple(map(tuple, red_hue)), tuple(map(tuple, blue_hue))
    hue8, _, chroma = _chroma_planes(colour_space)
    plain = _hue_classes(hue8, chroma, hue_table(red_key), hue_table(blue_key))
    wide = _hue_classes(hue8, chroma, *clipped_hue_tables(red_key, blue_key))
    half = s_min // 2
    yclip, yhi_half = _y_bounds(colour_space, CLIPPED, half)
    _, yhi_vivid = _y_bounds(colour_space, CLIPPED, max(CLIPPED_HUE_S_MIN, half))
    cls = np.where(plain != NONE, plain, wide)
    yhi = np.where(plain != NONE, yhi_half, yhi_vivid)
    cls = np.where(yhi < 0, NONE, cls).astype(np.uint32)
    yclip = np.clip(yclip, 0, 255).astype(np.uint32)  # ≤ y0 + 249.5 / a: max(R, G, B) - a(Y - y0) is never < 0
    yhi = np.where(cls == NONE, 0, np.clip(yhi, 0, 255)).astype(np.uint32)
    return (yclip | (yhi << 8) | (cls << 16) | (yclip << 24)).reshape(-1)


@functools.lru_cache(maxsize=4)
def saturation_table(colour_space: str) -> np.ndarray:
    """(65536,) uint8 table indexed by ``U << 8 | V``: the greatest Y whose max(R, G, B) rounds to 255 or less.

    A balanced pixel above it has a channel the BGR path's gains saturate at 255
    (:func:`~rangebearing.core.color.apply_gains`), which moves its hue and
    saturation in a way no (U, V) table holds.
    """
    a, y0 = COLOUR_SPACES[colour_space][:2]
    _, top, _ = _chroma_planes(colour_space)
    return np.clip(np.floor(y0 + (255.5 - top) / a), 0, 255).astype(np.uint8).reshape(-1)
