"""Hue, saturation and value thresholds derived from a landmark's own band pixels.

Pure: HSV arrays and band positions in, thresholds out. Hue follows OpenCV's
8-bit convention (0–179, degrees / 2). Red straddles hue 0, so its statistics
are taken on hue shifted by 90 (red near 90, far from the wrap) and shifted
back, which may split the range in two, e.g. ``[(0, 9), (170, 179)]``.
"""

from __future__ import annotations

import dataclasses
from typing import Optional, Sequence, Tuple

import numpy as np

from .._compat import frozen
from ..errors import CalibrationError
from .params import DetectionParams
from .types import XY

HueRange = Tuple[int, int]


@frozen
class ColourRanges:
    """Thresholds for :func:`rangebearing.core.color.class_masks` and what they came from."""

    red_hue: Tuple[HueRange, ...]
    blue_hue: Tuple[HueRange, ...]
    s_min: int
    v_min: int
    red_pixels: int
    blue_pixels: int


@frozen
class Margins:
    """How far past the measured pixels the thresholds reach.

    ``hue`` is added to the 1st–99th percentile hue span (OpenCV units);
    ``s_frac``/``v_frac`` scale the 5th percentile of saturation and value
    down (shadow, a dimmer corner of the room); ``s_floor``/``v_floor`` keep
    grey and black out whatever the pixels say.
    """

    hue: int = 6
    min_half_width: int = 5
    s_frac: float = 0.6
    v_frac: float = 0.5
    s_floor: int = 50
    v_floor: int = 20


def band_core(hsv: np.ndarray, centre_xy: XY, width_px: float, height_px: float, core: float = 0.6) -> np.ndarray:
    """HSV pixels (N, 3) of the central ``core`` share of a band's box.

    Parameters
    ----------
    hsv : (H, W, 3) uint8 array
    centre_xy : (x, y)
        The band's centroid, pixels.
    width_px, height_px : float
        The band's size in the image; only the middle ``core`` of each is
        taken, away from the white body, the other band and the background.
    """
    h, w = hsv.shape[:2]
    hw, hh = max(0.5, core * width_px / 2), max(0.5, core * height_px / 2)
    x0, x1 = round(float(centre_xy[0]) - hw), round(float(centre_xy[0]) + hw) + 1
    y0, y1 = round(float(centre_xy[1]) - hh), round(float(centre_xy[1]) + hh) + 1
    return hsv[max(0, y0) : min(h, y1), max(0, x0) : min(w, x1)].reshape(-1, 3)


def _hue_span(hue: np.ndarray, shift: int, m: Margins) -> Tuple[HueRange, ...]:
    h = (hue.astype(np.int64) + shift) % 180
    lo, mid, hi = np.percentile(h, [1, 50, 99])
    lo = int(np.floor(min(lo, mid - m.min_half_width))) - m.hue
    hi = int(np.ceil(max(hi, mid + m.min_half_width))) + m.hue
    if hi - lo >= 179:
        raise CalibrationError("the band's hues spread over the whole hue circle: it is not one colour")
    lo, hi = lo - shift, hi - shift
    if lo < 0:
        return ((0, hi), (180 + lo, 179)) if hi >= 0 else ((180 + lo, 180 + hi),)
    if hi > 179:
        return ((0, hi - 180), (lo, 179))
    return ((lo, hi),)


def _overlap(a: Sequence[HueRange], b: Sequence[HueRange]) -> bool:
    return any(lo1 <= hi2 and lo2 <= hi1 for lo1, hi1 in a for lo2, hi2 in b)


def derive_ranges(red: np.ndarray, blue: np.ndarray, margins: Optional[Margins] = None) -> ColourRanges:
    """Thresholds that accept the given red and blue band pixels with margins.

    Parameters
    ----------
    red, blue : (N, 3) uint8 arrays
        HSV pixels of each band (:func:`band_core`), from one or many frames.
    margins : Margins

    Returns
    -------
    ColourRanges

    Raises
    ------
    CalibrationError
        Too few pixels (under 20 in a band), a band that is not saturated (a
        grey or washed-out band: fix the light or the exposure first), or red
        and blue ranges that overlap.
    """
    for name, px in (("red", red), ("blue", blue)):
        if len(px) < 20:
            raise CalibrationError(f"only {len(px)} {name} band pixels: bring the landmark closer")
    m = margins or Margins()
    red_hue = _hue_span(red[:, 0], 90, m)
    blue_hue = _hue_span(blue[:, 0], 0, m)
    if _overlap(red_hue, blue_hue):
        raise CalibrationError(f"red hues {red_hue} and blue hues {blue_hue} overlap: the bands look alike")
    s5 = min(np.percentile(red[:, 1], 5), np.percentile(blue[:, 1], 5))
    v5 = min(np.percentile(red[:, 2], 5), np.percentile(blue[:, 2], 5))
    if s5 < m.s_floor / m.s_frac:
        raise CalibrationError(
            f"the bands are barely saturated (5th percentile S = {s5:.0f} of 255): the light is too dim or "
            "the frame is over-exposed, or white balance is far off"
        )
    return ColourRanges(
        red_hue=red_hue,
        blue_hue=blue_hue,
        s_min=int(max(m.s_floor, np.floor(s5 * m.s_frac))),
        v_min=int(max(m.v_floor, np.floor(v5 * m.v_frac))),
        red_pixels=len(red),
        blue_pixels=len(blue),
    )


def widen(hue: Sequence[HueRange], by: int) -> Tuple[HueRange, ...]:
    """Hue ranges grown by ``by`` on each side, wrapping at 0/179 (for a relaxed search)."""
    out = []
    for lo, hi in hue:
        lo, hi = lo - by, hi + by
        if lo < 0:
            out += [(0, hi), (180 + lo, 179)]
        elif hi > 179:
            out += [(lo, 179), (0, hi - 180)]
        else:
            out.append((lo, hi))
    return tuple(out)


RELAXED_HUE = 6  # OpenCV hue units (12°) the second look's hue ranges reach further on each side


def relaxed_hues(cfg: DetectionParams) -> DetectionParams:
    """``cfg`` with the hue ranges of the second look (:func:`.balance.second_look`): each reaching
    ``RELAXED_HUE`` further on both sides.

    The second look is for another camera's and another maker's bands (:func:`.color.relaxed_floors`):
    paint whose hue is ours turned by up to ±15° in display space (a crimson leaning magenta, a blue
    leaning violet or cyan), a tone curve or a white balance that turns it further. Frame-wide these
    ranges would let in orange and violet things; the second look's candidates must stand apart from
    every landmark found and be no stripe (cut on both sides), as at its lower floors. The calibrated
    red and blue ranges lie far apart (blue ends near 132, red starts near 165), so the two never meet.
    """
    return dataclasses.replace(cfg, red_hue=widen(cfg.red_hue, RELAXED_HUE), blue_hue=widen(cfg.blue_hue, RELAXED_HUE))


def search_ladder(
    red_hue: Sequence[HueRange], blue_hue: Sequence[HueRange], s_min: int, v_min: int
) -> Tuple[Tuple[Tuple[HueRange, ...], Tuple[HueRange, ...], int, int], ...]:
    """Ever looser thresholds to find a landmark the current ones miss: the current ones first."""
    steps = [(0, 1.0), (6, 0.75), (12, 0.5), (18, 0.35)]
    return tuple(
        (widen(red_hue, d), widen(blue_hue, d), max(20, int(s_min * f)), max(10, int(v_min * f))) for d, f in steps
    )
