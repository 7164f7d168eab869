"""Pixels a white-balance gain above one saturates: classed by their colour before the saturation.

:func:`.color.apply_gains` saturates a channel at 255. A pixel it pushes there
reads V ≥ ``CLIPPED`` and falls under :func:`.color.sv_gate`'s and
:func:`.color.clip_of`'s clipped rules (half the saturation floor, wider hues):
those are for a *sensor* that clipped, whose chroma is lost. Here the chroma is
not lost, only cut by the saturation: a bright white body, (237, 234, 227) BGR
under a blue gain of 1.15, becomes (255, 227, 206), S 48 of hue 110, and at
half of ``s_min`` the whole body was a blue band (``photoreal-alt`` s22534 f15:
a landmark at 0.43 m lost to an over-exposed frame), while a washed-out red band
just under the shoulder, (170, 170, 245), under a red gain of 1.1 has its true
S 94 cut to 85. Such a pixel is classed from its balanced colour before the
saturation (hue and saturation are ratios: no clip) at the normal floors.
A pixel clipped before the gains keeps the clipped rules.
"""

from __future__ import annotations

from typing import Optional, Tuple

import cv2
import numpy as np

from .color import CLIPPED, Gains, HueRanges, clipped_mask, hue_in

PUSHING_GAIN = 1.02  # a gain at most this far above one saturates no pixel that matters (apply_gains skips it)


def pushed_over(small: np.ndarray, gains: Gains, v: np.ndarray) -> Optional[Tuple[np.ndarray, np.ndarray]]:
    """(rows, cols) of the pixels of ``small`` (BGR uint8, before the gains) that read V ≥ ``CLIPPED``
    after the gains (``v``: V after them) but had no channel clipped before; ``None`` when there are none."""
    if max(gains) <= PUSHING_GAIN:
        return None
    _, over = cv2.threshold(v, CLIPPED - 1, 255, cv2.THRESH_BINARY)
    if not cv2.countNonZero(over):
        return None
    over = cv2.bitwise_and(over, cv2.bitwise_not(clipped_mask(small)))
    if not cv2.countNonZero(over):
        return None
    return np.nonzero(over)


def unsaturated_hs(px: np.ndarray, gains: Gains) -> Tuple[np.ndarray, np.ndarray]:
    """OpenCV-scaled hue (0–179) and saturation (0–255), uint8 columns, of ``(N, 3)`` BGR pixels under
    ``gains`` without the saturation at 255."""
    bal = px.reshape(-1, 1, 3).astype(np.float32) * np.asarray(gains, np.float32)
    hsv = cv2.cvtColor(bal / max(1.0, float(bal.max())), cv2.COLOR_BGR2HSV)  # float: H in degrees, S in 0–1
    hue = np.round(hsv[..., 0] / 2.0).astype(np.int32) % 180
    sat = np.round(hsv[..., 1] * 255.0)
    return hue.astype(np.uint8), sat.astype(np.uint8)


def reclass_pushed(red: np.ndarray, blue: np.ndarray, small: np.ndarray, gains: Gains,
                   where: Optional[Tuple[np.ndarray, np.ndarray]], red_hue: HueRanges, blue_hue: HueRanges,
                   s_min: int) -> Tuple[np.ndarray, np.ndarray]:
    """The red and blue masks (0/255) with the pixels at ``where`` (:func:`pushed_over`) classed by their
    unsaturated hue and saturation at ``s_min`` (their V is over any floor); new arrays where changed."""
    if where is None:
        return red, blue
    hue, sat = unsaturated_hs(small[where], gains)
    vivid = sat >= s_min
    red, blue = red.copy(), blue.copy()
    red[where] = np.where(vivid & (hue_in(hue, red_hue) > 0), 255, 0)[:, 0]
    blue[where] = np.where(vivid & (hue_in(hue, blue_hue) > 0), 255, 0)[:, 0]
    return red, blue
