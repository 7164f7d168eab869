"""The downscaled frame as the structure search reads it under one balance, each view made once per frame.

A full scan searches the frame under its balance and then takes a second look at
lower colour floors (:func:`.balance.second_look`) under the same gains: both read the
same HSV image, its channels, the red and blue hue masks and the clipped pixels, which
differ only in their saturation and value gate. :class:`SearchImage` keeps them, so the
second look costs one gate and two ``and``\\ s instead of a second conversion.
"""

from __future__ import annotations

from typing import Dict, Optional, Tuple

import cv2
import numpy as np

from .color import Gains, apply_gains, class_hues, clip_of, clipped_mask, clipped_v, sv_gate, to_hsv
from .gain_clip import pushed_over, reclass_pushed
from .params import DetectionParams


class SearchImage:
    """The views of one downscaled BGR frame (``small``, uint8) under ``gains``, made on first use."""

    __slots__ = ("_clip_v", "_clipped", "_hsv_split", "_hues", "_pushed", "_vivid_clip", "gains", "hsv", "small")

    def __init__(self, small: np.ndarray, gains: Gains) -> None:
        self.small, self.gains = small, gains
        self.hsv: np.ndarray = to_hsv(apply_gains(small, gains))
        self._hsv_split: Optional[Tuple[np.ndarray, ...]] = None
        self._hues: Dict[tuple, Tuple[np.ndarray, np.ndarray]] = {}  # the hue masks by the ranges they are of
        self._clipped: Optional[Tuple[Optional[np.ndarray]]] = None
        self._pushed: Optional[tuple] = None  # (gain_clip.pushed_over,) once made
        self._clip_v: Optional[np.ndarray] = None  # color.clipped_v: every gate and hue lookup reads it
        self._vivid_clip: Optional[np.ndarray] = None  # color.clip_of: the same for every hue range

    def clipped(self) -> Optional[np.ndarray]:
        """Pixels clipped before the gains, when a gain below one may have hidden it (else ``None``)."""
        if self._clipped is None:
            self._clipped = (clipped_mask(self.small) if min(self.gains) < 0.98 else None,)
        return self._clipped[0]

    def class_masks(self, cfg: DetectionParams, s_min: int, v_min: int) -> Tuple[np.ndarray, np.ndarray]:
        """:func:`.color.class_masks` of the HSV image at these floors (0/255 uint8; the same arrays' values)."""
        if self._hsv_split is None:
            self._hsv_split = tuple(cv2.split(self.hsv))
        h, s, v = self._hsv_split
        if self._clip_v is None:
            self._clip_v = clipped_v(v, self.clipped())
        key = (tuple(map(tuple, cfg.red_hue)), tuple(map(tuple, cfg.blue_hue)))
        if key not in self._hues:
            if self._vivid_clip is None:
                self._vivid_clip = clip_of(s, self._clip_v)
            self._hues[key] = class_hues(h, cfg.red_hue, cfg.blue_hue, self._vivid_clip)
        red_h, blue_h = self._hues[key]
        sv = sv_gate(s, v, s_min, v_min, self._clip_v)
        if self._pushed is None:
            self._pushed = (pushed_over(self.small, self.gains, v),)
        return reclass_pushed(cv2.bitwise_and(red_h, sv), cv2.bitwise_and(blue_h, sv), self.small, self.gains,
                              self._pushed[0], cfg.red_hue, cfg.blue_hue, s_min)
