"""Colour stages: white balance, HSV conversion and the red/blue hue thresholds.

All functions take and return numpy arrays and do no I/O. Hue follows OpenCV's
8-bit convention (0–179, i.e. degrees / 2); saturation and value are 0–255.
"""

from __future__ import annotations

import functools
from typing import Optional, Sequence, Tuple

import cv2
import numpy as np

Gains = Tuple[float, float, float]
HueRanges = Sequence[Tuple[int, int]]

UNIT_GAINS: Gains = (1.0, 1.0, 1.0)


NEUTRAL_SAT = 0.25  # saturation scale of the neutral-pixel weight exp(-(S / NEUTRAL_SAT)^2)
DARK, CLIPPED = 20, 250  # pixels outside this max-channel range carry no colour information
BALANCE_ITERATIONS = 3


def grey_world_gains(bgr: np.ndarray, limit: float = 2.0) -> Gains:
    """Channel gains that make the frame's *neutral* surfaces neutral (a robust grey-world).

    Parameters
    ----------
    bgr : (H, W, 3) uint8 array
        Any image in BGR order; it is area-averaged to about 40×30 first, so a
        downscaled frame is plenty.
    limit : float
        Gains are clipped to ``[1/limit, limit]`` so no scene can swing the
        balance arbitrarily.

    Returns
    -------
    (g_b, g_g, g_r) : tuple of float
        Multiply channel c by ``g_c``; a neutral frame gives ``(1, 1, 1)``.

    Notes
    -----
    Plain grey-world averages every pixel, so a navy carpet or a red wall
    pulls the balance towards its complement (the white body turns cyan).
    Here very dark pixels (max channel < 20: noise, no hue) and clipped ones
    (> 250: the channel ratio is lost) are ignored, and each remaining pixel
    is weighted by ``exp(-(S/0.25)²)`` of its saturation *after* the current
    gains, iterated three times from unit gains. A colour cast shifts every
    surface alike and is removed; a strongly coloured surface (S ≈ 0.6–0.9)
    weighs e^-6 to e^-13 and is ignored however large it is. With no
    near-neutral pixel at all the gains stay at one.
    """
    h, w = bgr.shape[:2]
    f = max(1, min(h // 30, w // 40))
    tiny = cv2.resize(bgr, (max(1, w // f), max(1, h // f)), interpolation=cv2.INTER_AREA) if f > 1 else bgr
    pixels = tiny.reshape(-1, 3).astype(np.float32)
    gains = np.ones(3, np.float64)
    unbalanced = None  # the weighted mean colour of the frame as it is, once measured
    # (numpy's values throughout, without the Python layers of np.clip, .mean() and .sum() on 3 numbers)
    for _ in range(BALANCE_ITERATIONS):
        g = gains.tolist()
        q = apply_gains(tiny, tuple(g)) if g != [1.0, 1.0, 1.0] else tiny
        if q is tiny and unbalanced is not None:  # gains too near one to change a pixel: the same weights again
            mean = unbalanced * gains
        else:
            _, s, v = cv2.split(cv2.cvtColor(q, cv2.COLOR_BGR2HSV))
            # weight: neutral-ness from S (after the gains), zero for dark or clipped V (one table each)
            wgt = cv2.multiply(cv2.LUT(s, _neutral_table()), cv2.LUT(v, _valid_table()), scale=1.0 / 255.0)
            wv = wgt.reshape(-1).astype(np.float32)
            total = float(np.add.reduce(wv))
            if total < 1e-3 * 255.0 * len(wv):  # nothing near neutral: keep what we have
                break
            weighted = (wv @ pixels) / total
            if q is tiny:
                unbalanced = weighted
            mean = weighted * gains  # the balanced colour of the neutral surfaces
        gains = np.minimum(np.maximum(gains * (np.add.reduce(mean) / 3) / np.maximum(mean, 1e-3), 1.0 / limit), limit)
    return tuple(gains.tolist())  # type: ignore[return-value]


@functools.lru_cache(maxsize=1)
def _neutral_table() -> np.ndarray:
    """uint8 LUT over S (0–255): 255·exp(-(S/255 / NEUTRAL_SAT)²)."""
    s = np.arange(256, dtype=np.float64) / 255.0
    return np.round(255.0 * np.exp(-np.square(s / NEUTRAL_SAT))).astype(np.uint8).reshape(256, 1)


@functools.lru_cache(maxsize=1)
def _valid_table() -> np.ndarray:
    """uint8 LUT over V: 255 where DARK ≤ V ≤ CLIPPED, else 0."""
    t = np.zeros((256, 1), np.uint8)
    t[DARK : CLIPPED + 1] = 255
    return t


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


CLIPPED_HUE_REACH = 15  # OpenCV hue units (30°) a clipped band's hue may lie beyond its class's range


@functools.lru_cache(maxsize=16)
def clipped_hue_tables(red_hue: Tuple[Tuple[int, int], ...], blue_hue: Tuple[Tuple[int, int], ...]
                       ) -> Tuple[np.ndarray, np.ndarray]:
    """``cv2.LUT`` tables (255 inside) of the red and the blue hues a *clipped* pixel of each class may show.

    A band whose strongest channel clips (over-exposed: 1–2 stops over, a spotlight) keeps the
    difference of its two lesser channels while its chroma, max − min, shrinks: its hue's offset
    from the paint's primary grows by the clip factor (×2–4 at 1–2 stops over), a red band reading
    orange or magenta, a blue one cyan or violet. Each class's range reaches ``CLIPPED_HUE_REACH``
    further on both sides for clipped pixels; a hue both reaches take goes to the nearer range,
    and none is taken from the other class's own range.
    """
    hue = np.arange(180)

    def distance(ranges: Tuple[Tuple[int, int], ...]) -> np.ndarray:  # circular distance to the ranges (0 inside)
        d = np.full(180, 180)
        for lo, hi in ranges:
            inside = (hue >= lo) & (hue <= hi)
            off = np.minimum(np.minimum(np.abs(hue - lo), 180 - np.abs(hue - lo)),
                             np.minimum(np.abs(hue - hi), 180 - np.abs(hue - hi)))
            d = np.minimum(d, np.where(inside, 0, off))
        return d

    d_red, d_blue = distance(red_hue), distance(blue_hue)
    tables = []
    for mine, other in ((d_red, d_blue), (d_blue, d_red)):
        table = np.zeros((256, 1), np.uint8)
        table[:180, 0] = np.where((mine <= CLIPPED_HUE_REACH) & (mine < other) & (other > 0), 255, 0)
        tables.append(table)
    return tables[0], tables[1]


def class_hues(h: np.ndarray, red_hue: HueRanges, blue_hue: HueRanges, clip: Optional[np.ndarray] = None
               ) -> Tuple[np.ndarray, np.ndarray]:
    """0/255 masks of the red and the blue hues; where ``clip`` (0/255) is set, :func:`clipped_hue_tables`'
    wider ones."""
    red_key, blue_key = tuple(map(tuple, red_hue)), tuple(map(tuple, blue_hue))
    red, blue = cv2.LUT(h, hue_table(red_key)), cv2.LUT(h, hue_table(blue_key))
    if clip is None or not cv2.countNonZero(clip):
        return red, blue
    red_wide, blue_wide = clipped_hue_tables(red_key, blue_key)
    return (cv2.bitwise_or(red, cv2.bitwise_and(cv2.LUT(h, red_wide), clip)),
            cv2.bitwise_or(blue, cv2.bitwise_and(cv2.LUT(h, blue_wide), clip)))


CLIPPED_HUE_S_MIN = 80  # a clipped pixel paler than this (a white body's highlight: S < 80) keeps the plain ranges


def clip_of(s: np.ndarray, clip: np.ndarray) -> np.ndarray:
    """0/255 mask of the pixels :func:`class_hues` reads with the clipped pixels' wider hues: the clipped
    ones (``clip``, :func:`clipped_v`) no paler than ``CLIPPED_HUE_S_MIN``.

    A white body's clipped highlight under a tinted light (a red wall's bounce, a warm lamp) reads
    (255, 220, 200): its hue is a red band's widened one, but it is as pale as the body the column
    scan calls white, and it must stay white there.
    """
    _, vivid = cv2.threshold(s, CLIPPED_HUE_S_MIN - 1, 255, cv2.THRESH_BINARY)
    return cv2.bitwise_and(clip, vivid)


def clipped_v(v: np.ndarray, clipped: Optional[np.ndarray] = None) -> np.ndarray:
    """0/255 mask of the pixels clipped after the gains (V ≥ ``CLIPPED``) or, per ``clipped`` (0/255), before them."""
    _, clip = cv2.threshold(v, CLIPPED - 1, 255, cv2.THRESH_BINARY)
    return clip if clipped is None else cv2.max(clip, clipped)


def clipped_mask(bgr: np.ndarray) -> np.ndarray:
    """0/255 mask of pixels with any channel at ``CLIPPED`` or above, of a BGR uint8 image *before* its gains.

    A gain below one scales a clipped channel under the threshold (a red band in
    a spotlight, (150, 160, 252) BGR, becomes (167, 163, 224)), yet it stays a
    lower bound of the light: the pixel is still clipped, and :func:`sv_gate`
    must know it.
    """
    _, over = cv2.threshold(bgr, CLIPPED - 1, 255, cv2.THRESH_BINARY)
    b, g, r = cv2.split(over)
    return cv2.max(cv2.max(b, g), r)


def sv_gate(s: np.ndarray, v: np.ndarray, s_min: int, v_min: int, clip: np.ndarray) -> np.ndarray:
    """0/255 mask of S ≥ s_min and V ≥ v_min; where clipped (``clip``, :func:`clipped_v`), S ≥ s_min/2 suffices.

    A clipped pixel has lost part of its chroma to saturation of the sensor
    (a band in a spotlight reads (255, 200, 190)): its hue is still right but
    its saturation is lower than the paint's. :func:`clipped_v` marks the pixels
    clipped after the gains (V ≥ 250) and those clipped before them (:func:`clipped_mask`).
    """
    _, s_ok = cv2.threshold(s, s_min - 1, 255, cv2.THRESH_BINARY)
    _, v_ok = cv2.threshold(v, v_min - 1, 255, cv2.THRESH_BINARY)
    _, s_half = cv2.threshold(s, s_min // 2 - 1, 255, cv2.THRESH_BINARY)
    return cv2.bitwise_or(cv2.bitwise_and(s_ok, v_ok), cv2.bitwise_and(s_half, clip))


def hue_mask(hsv: np.ndarray, hue_ranges: HueRanges, s_min: int, v_min: int) -> np.ndarray:
    """Binary mask (0/255 uint8) of pixels inside any hue range with S ≥ s_min and V ≥ v_min.

    Red wraps around hue 0, so it is given as two ranges, e.g. ``[(0, 10), (165, 179)]``.
    """
    h, s, v = cv2.split(hsv)
    return cv2.bitwise_and(hue_in(h, hue_ranges), sv_gate(s, v, s_min, v_min, clipped_v(v)))


def class_masks(
    hsv: np.ndarray, red_hue: HueRanges, blue_hue: HueRanges, s_min: int, v_min: int,
    clipped: Optional[np.ndarray] = None,
) -> Tuple[np.ndarray, np.ndarray]:
    """The red and the blue :func:`hue_mask` of one image, sharing the channel split and S/V gate
    (``clipped``: see :func:`sv_gate`)."""
    h, s, v = cv2.split(hsv)
    clip = clipped_v(v, clipped)
    sv = sv_gate(s, v, s_min, v_min, clip)
    red, blue = class_hues(h, red_hue, blue_hue, clip_of(s, clip))
    return cv2.bitwise_and(red, sv), cv2.bitwise_and(blue, sv)


# a second look (core/balance.py): the class floors another camera's darker or paler bands fall under
RELAXED_S_SHARE = 2 / 3  # of s_min: paint ×0.7 saturation, 2×2 chroma blocks, a veil
RELAXED_V_SHARE = 0.6  # of v_min: 1–2 stops under, a filmic toe
RELAXED_WHITE_V = DARK  # the white body's least V (the column scan's is 40): a body 1–2 stops under


def relaxed_floors(s_min: int, v_min: int) -> Tuple[int, int]:
    """The saturation and value floors of the second look (:func:`.balance.second_look`) for ``s_min``, ``v_min``.

    A camera that exposes 1–2 stops under, or whose tone curve has a deep toe,
    leaves a white body at V 20–40 and a band at V 15–25; another maker's paint
    (saturation ×0.7), a veil, or chroma coded in 2×2 blocks leave a band at
    S 60–90. Frame-wide these floors let in the rims and stripes of everything
    red or blue; they serve only a search whose candidates must stand apart from
    every landmark found without them.
    """
    return round(s_min * RELAXED_S_SHARE), round(v_min * RELAXED_V_SHARE)


@functools.lru_cache(maxsize=16)
def ramp_table(lo: int, width: int) -> np.ndarray:
    """uint8 lookup table for ``cv2.LUT``: 0 up to ``lo``, rising linearly to 255 at ``lo + width``."""
    ramp = np.clip((np.arange(256, dtype=np.float64) - lo) / float(width), 0.0, 1.0)
    return np.round(255.0 * ramp).astype(np.uint8).reshape(256, 1)
