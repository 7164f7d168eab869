"""Band search on a camera's YUV420 stream: red and blue masks straight from the chroma planes.

The Pi's ISP can hand over a second stream (``lores``, YUV420) beside the BGR
frame at no CPU cost. Its U and V planes are already at half resolution,
which is the fast path's downscale step, so the search needs neither the
BGR average nor the BGR→HSV conversion: each pixel's class comes from one
table lookup on its (U, V) pair and a comparison of its Y with two bounds
from the same table. The result is the mask pair
:func:`rangebearing.core.detect.region_masks` makes from a BGR frame; the
landmarks are then measured on the BGR frame as before.

Why a table on (U, V) is exact: RGB = a·(Y − y0) + d(U, V), the same ``a·(Y − y0)``
added to every channel, so the channel differences (hence HSV hue) depend on
U and V alone, as does the chroma C = max − min. Saturation C / max and value
max = a·(Y − y0) + max(d) turn into bounds on Y: ``V ≥ v_min`` is
``Y ≥ ylo(U, V)`` and ``S ≥ s_min`` is ``Y ≤ yhi(U, V)``; the BGR path's rules
for clipped pixels (V ≥ 250) are a second table (:mod:`.yuv_table`). Grey-world
gains (a diagonal gain on R, G, B) are an affine map of (Y, U, V), applied to
the planes before the lookup when they are not within 2 % of one; the few
pixels a gain above one would saturate at 255 are classed from their BGR.
Channel clipping at 0 is not modelled.
"""

from __future__ import annotations

import dataclasses
from typing import Optional, Sequence, Tuple

import cv2
import numpy as np

from .._compat import frozen
from .color import UNIT_GAINS, Gains, class_masks, clipped_mask, grey_world_gains, relaxed_floors, to_hsv
from .colour_tune import relaxed_hues
from .denoise import Box, band_masks, none_apart_filtered
from .gain_clip import pushed_over, reclass_pushed
from .params import DetectionParams
from .structure import Found, search, search_apart
from .types import LandmarkGeometry
from .yuv_table import BLUE, COLOUR_SPACES, NONE, RED, _rgb_matrix, class_table, clipped_table, saturation_table

__all__ = ["BLUE", "COLOUR_SPACES", "NONE", "RED", "Yuv420", "chroma_masks", "class_table", "half_luma",
           "yuv420_from_bgr", "yuv420_planes", "yuv_grey_world_gains", "yuv_search", "yuv_to_bgr"]

# B'G'R' → Cb, Cr (8 bit, limited range), rows U, V with a constant column: OpenCV's I420 coefficients
_FORWARD = {"smpte170m": np.array([[0.439, -0.291, -0.148, 128.0], [-0.071, -0.368, 0.439, 128.0]])}


@frozen
class Yuv420:
    """A YUV420 (I420) image as three uint8 planes, views into the camera's buffer where it has one.

    ``y`` is (H, W); ``u`` and ``v`` are (H/2, W/2), one chroma sample per 2×2
    block of Y. ``colour_space`` names the Y'CbCr matrix (:data:`COLOUR_SPACES`).
    """

    y: np.ndarray
    u: np.ndarray
    v: np.ndarray
    colour_space: str = "smpte170m"


def yuv420_from_bgr(bgr: np.ndarray) -> Yuv420:
    """What a camera's YUV420 stream would hold for a BGR frame (SMPTE 170M), for recorded and synthetic sources.

    Y is OpenCV's ``COLOR_BGR2YUV_I420``. Its chroma is point-sampled (the
    top-left pixel of each 2×2 block), where an ISP filters; here U and V are
    the same matrix applied to the frame's 2×2 block means instead (means
    commute with the matrix), the samples the search is meant to see. Width
    and height must be even.
    """
    h, w = bgr.shape[:2]
    if h % 2 or w % 2:
        raise ValueError(f"YUV420 needs an even width and height, not {w}×{h}")
    i420 = cv2.cvtColor(bgr, cv2.COLOR_BGR2YUV_I420)
    small = cv2.resize(bgr, (w // 2, h // 2), interpolation=cv2.INTER_AREA)
    uv = cv2.transform(small, _FORWARD["smpte170m"])
    chroma = i420[h:].reshape(-1)
    n = (w // 2) * (h // 2)
    chroma[:n] = uv[..., 0].reshape(-1)
    chroma[n:] = uv[..., 1].reshape(-1)
    return yuv420_planes(i420, w, h)


def yuv420_planes(buffer: np.ndarray, width_px: int, height_px: int, colour_space: str = "smpte170m") -> Yuv420:
    """Views of the Y, U and V planes of a YUV420 buffer laid out as Picamera2 maps it; nothing is copied.

    Parameters
    ----------
    buffer : (H * 3 / 2, stride) uint8 array
        Y (H rows of ``stride`` bytes), then U and V (H/2 rows of ``stride/2``
        bytes each). ``stride`` ≥ W; bytes past W (past W/2 in the chroma
        planes) are padding.
    width_px, height_px : int
        The image size (even).
    """
    w, h = int(width_px), int(height_px)
    if buffer.ndim != 2 or buffer.dtype != np.uint8 or buffer.shape[0] != h * 3 // 2 or buffer.shape[1] < w:
        raise ValueError(f"not a {w}×{h} YUV420 buffer: {buffer.dtype} {buffer.shape}")
    stride = buffer.shape[1]
    y = buffer[:h, :w]
    chroma = buffer[h:].reshape(-1)
    if not chroma.flags.c_contiguous:  # a strided view of a larger array: rows cannot be regrouped in place
        chroma = np.ascontiguousarray(chroma)
    planes = chroma.reshape(2, h // 2, stride // 2)
    return Yuv420(y, planes[0, :, : w // 2], planes[1, :, : w // 2], colour_space)


def _bgr_affine(colour_space: str, gains: Gains = UNIT_GAINS) -> np.ndarray:
    """3×4 matrix taking [Y, U, V, 1] to the balanced [B, G, R] (``gains`` are b, g, r)."""
    m, off = _rgb_matrix(colour_space)
    g = np.asarray(gains, np.float64)[::-1, None]  # rows of m are R, G, B
    return np.hstack([g * m, g * off[:, None]])[::-1].copy()


def yuv_to_bgr(y: np.ndarray, u: np.ndarray, v: np.ndarray, colour_space: str, gains: Gains = UNIT_GAINS
               ) -> np.ndarray:
    """BGR uint8 of three equal-sized planes, through the colour space's matrix and the gains (saturating)."""
    yuv = cv2.merge((np.ascontiguousarray(y), np.ascontiguousarray(u), np.ascontiguousarray(v)))
    return cv2.transform(yuv, _bgr_affine(colour_space, gains))


def yuv_grey_world_gains(yuv: Yuv420, limit: float = 2.0, y_half: Optional[np.ndarray] = None) -> Gains:
    """:func:`~rangebearing.core.color.grey_world_gains` of the same ~40×30 thumbnail the BGR path balances on.

    ``y_half`` is :func:`half_luma` of ``yuv.y`` when the caller has it (then
    every plane is shrunk from half resolution).
    """
    y_half = half_luma(yuv.y) if y_half is None else y_half
    h, w = y_half.shape
    f = max(1, min(h // 30, w // 40))
    size = (max(1, w // f), max(1, h // f))
    y, u, v = (cv2.resize(p, size, interpolation=cv2.INTER_AREA) for p in (y_half, yuv.u, yuv.v))
    return grey_world_gains(yuv_to_bgr(y, u, v, yuv.colour_space), limit)


def _balance(y: np.ndarray, u: np.ndarray, v: np.ndarray, gains: Gains, colour_space: str):
    """Planes of the balanced image: the gains on R, G, B as one affine map of (Y, U, V)."""
    m, off = _rgb_matrix(colour_space)
    g = np.diag(np.asarray(gains, np.float64)[::-1])  # gains are (b, g, r); rows of m are R, G, B
    inv = np.linalg.inv(m)
    a = inv @ g @ m
    b = inv @ (g @ off - off)
    out = cv2.transform(cv2.merge((y, u, v)), np.hstack([a, b[:, None]]))
    return cv2.split(out)


def half_luma(y: np.ndarray) -> np.ndarray:
    """Y averaged over each 2×2 block: the luma that goes with one chroma sample."""
    h, w = y.shape
    return cv2.resize(y[: h // 2 * 2, : w // 2 * 2], (w // 2, h // 2), interpolation=cv2.INTER_AREA)


def chroma_masks(yuv: Yuv420, cfg: DetectionParams, gains: Gains = UNIT_GAINS,
                 y_half: Optional[np.ndarray] = None) -> Tuple[np.ndarray, np.ndarray]:
    """Red and blue masks (0/255 uint8, half resolution) of a YUV420 image, before the majority filter.

    The same masks :func:`~rangebearing.core.color.class_masks` makes from the
    balanced, downscaled BGR frame (its clipped pixels' rules included, with the
    mask of pixels clipped before the gains), up to rounding and channel
    clipping.
    ``y_half`` is :func:`half_luma` of ``yuv.y`` when the caller has it.
    """
    y, u, v = half_luma(yuv.y) if y_half is None else y_half, yuv.u, yuv.v
    raw = None  # the unbalanced (U, V) index and Y, when a gain below one may hide a clipped channel
    if min(gains) < 0.98:
        raw = (_uv_index(u, v), y)
    unbalanced = (y, u, v)
    gains_applied = not all(abs(g - 1.0) <= 0.02 for g in gains)
    if gains_applied:
        y, u, v = _balance(y, np.ascontiguousarray(u), np.ascontiguousarray(v), gains, yuv.colour_space)
    keys = (yuv.colour_space, tuple(map(tuple, cfg.red_hue)), tuple(map(tuple, cfg.blue_hue)), int(cfg.s_min))
    idx = _uv_index(u, v)
    ylo, yhi, cls, _ = _lookup(class_table(*keys, int(cfg.v_min)), idx)
    ok = cv2.bitwise_and(cv2.compare(y, ylo, cv2.CMP_GE), cv2.compare(y, yhi, cv2.CMP_LE))
    red = cv2.bitwise_and(cv2.compare(cls, RED, cv2.CMP_EQ), ok)
    blue = cv2.bitwise_and(cv2.compare(cls, BLUE, cv2.CMP_EQ), ok)
    # the clipped pixels' rules (:func:`.yuv_table.clipped_table`): V clipped after the gains, or before them
    table = clipped_table(*keys)
    yclip, yhi, cls, _ = _lookup(table, idx)
    clip = cv2.compare(y, yclip, cv2.CMP_GE)
    if raw is not None:
        clip = cv2.bitwise_or(clip, cv2.compare(raw[1], _lookup(table, raw[0])[3], cv2.CMP_GE))
    ok = cv2.bitwise_and(clip, cv2.compare(y, yhi, cv2.CMP_LE))
    red = cv2.bitwise_or(red, cv2.bitwise_and(cv2.compare(cls, RED, cv2.CMP_EQ), ok))
    blue = cv2.bitwise_or(blue, cv2.bitwise_and(cv2.compare(cls, BLUE, cv2.CMP_EQ), ok))
    if gains_applied and max(gains) > 1.0:  # a gain above one may saturate a channel at 255, as apply_gains does
        over = cv2.compare(y, saturation_table(yuv.colour_space).take(idx), cv2.CMP_GT)
        if cv2.countNonZero(over):
            _saturated(red, blue, np.nonzero(over), unbalanced, cfg, gains, yuv.colour_space)
    return red, blue


def _saturated(red: np.ndarray, blue: np.ndarray, where: Tuple[np.ndarray, np.ndarray], planes: Tuple[np.ndarray, ...],
               cfg: DetectionParams, gains: Gains, colour_space: str) -> None:
    """Class the pixels at ``where`` as the BGR path does, from their balanced and saturated BGR (in place)."""
    y, u, v = (p[where].reshape(-1, 1) for p in planes)
    raw = yuv_to_bgr(y, u, v, colour_space)
    clipped = clipped_mask(raw) if min(gains) < 0.98 else None
    hsv = to_hsv(yuv_to_bgr(y, u, v, colour_space, gains))
    r, b = class_masks(hsv, cfg.red_hue, cfg.blue_hue, cfg.s_min, cfg.v_min, clipped)
    r, b = reclass_pushed(r, b, raw, gains, pushed_over(raw, gains, hsv[..., 2]), cfg.red_hue, cfg.blue_hue, cfg.s_min)
    red[where], blue[where] = r[:, 0], b[:, 0]


def _uv_index(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """uint16 ``U << 8 | V`` of two uint8 planes: the tables' index."""
    idx = u.astype(np.uint16)
    idx <<= 8
    idx |= v
    return idx


def _lookup(table: np.ndarray, idx: np.ndarray) -> Tuple[np.ndarray, ...]:
    """The four uint8 bytes (low first) of a packed uint32 table at each index, as planes."""
    return tuple(cv2.split(table.take(idx).view(np.uint8).reshape(*idx.shape, 4)))


class WindowHsv:
    """The balanced half-resolution HSV image of a YUV420 frame, converted only where it is indexed.

    ``hsv[rows, cols]`` (two slices) is what ``to_hsv(apply_gains(small, gains))[rows, cols]``
    would be on the BGR path, up to rounding: the structure check reads a few
    windows of it, so the frame is never converted whole.
    """

    def __init__(self, y_half: np.ndarray, yuv: Yuv420, gains: Gains) -> None:
        self._planes = (y_half, yuv.u, yuv.v)
        self._space = yuv.colour_space
        self._gains = gains
        self.shape = (*y_half.shape, 3)
        self._last: Tuple[object, Optional[np.ndarray]] = (None, None)

    def __getitem__(self, win: Tuple[slice, slice]) -> np.ndarray:
        key = tuple((s.start, s.stop, s.step) for s in win)
        if self._last[0] == key:  # the structure check reads S and V of one window in a row
            return self._last[1]  # type: ignore[return-value]
        y, u, v = (p[win] for p in self._planes)
        out = np.zeros((*y.shape, 3), np.uint8) if y.size == 0 else to_hsv(yuv_to_bgr(y, u, v, self._space,
                                                                                      self._gains))
        self._last = (key, out)
        return out


def yuv_search(
    yuv: Yuv420, cfg: DetectionParams, gains: Gains, ksize: int, geometry: LandmarkGeometry,
    y_half: Optional[np.ndarray] = None, relaxed: Optional[Sequence[Box]] = None,
) -> Found:
    """:func:`~rangebearing.core.detect.search_candidates` with the band search on the YUV420 planes.

    ``cfg.downscale`` must be 2 (the chroma planes' scale); candidates are in
    full-resolution pixels of the frame the planes belong to. ``relaxed``: the second look, as there.
    """
    y_half = half_luma(yuv.y) if y_half is None else y_half
    if relaxed is not None:
        s_min, v_min = relaxed_floors(cfg.s_min, cfg.v_min)
        cfg = dataclasses.replace(relaxed_hues(cfg), s_min=s_min, v_min=v_min)
    red, blue = chroma_masks(yuv, cfg, gains, y_half)
    if relaxed is not None and none_apart_filtered(red, blue, relaxed, 2, ksize):
        return Found([], lambda: True)  # as search_apart says of filtered masks with nothing apart
    red, blue = band_masks(red, blue, ksize)
    min_area = max(2, int(cfg.min_band_px * cfg.min_band_px / 4))
    hsv = WindowHsv(y_half, yuv, gains)
    if relaxed is not None:
        return search_apart(red, blue, hsv, 2, geometry, cfg.max_landmarks, min_area, relaxed)
    return search(red, blue, hsv, 2, geometry, cfg.max_landmarks, min_area)
