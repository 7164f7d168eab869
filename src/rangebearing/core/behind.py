"""Landmarks behind nearer ones: the sides a nearer landmark hides, and bands that run on behind it.

The structure search (:mod:`.structure`) takes the nearest landmarks (tallest white bodies) first.
A farther one standing partly behind a nearer one is cut at the nearer one's limb: that side of
it is no limb (:func:`occluded_sides`). Its bands, followed along their rows to find its columns
where something hides its white body (:func:`.fragments.extend_along_bands`), end at the nearer
landmark, not at its own limb; at about the same image height they run on into the nearer one's
bands, as a red wall's would. :func:`without_nearer` takes the nearer landmarks out of the masks
the bands are followed in, so they end where the nearer one hides them.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, List, Sequence, Tuple

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from .structure import Candidate


def without_nearer(
    red: np.ndarray, blue: np.ndarray, nearer: Sequence[Candidate], scale: int
) -> Tuple[np.ndarray, np.ndarray]:
    """``red`` and ``blue`` (downscaled masks) with the boxes of the ``nearer`` candidates (full-resolution
    pixels, red top to blue bottom) cleared; the masks themselves when there are none."""
    if not nearer:
        return red, blue
    red, blue = red.copy(), blue.copy()
    _clear(red, blue, nearer, scale)
    return red, blue


def _clear(red: np.ndarray, blue: np.ndarray, nearer: Sequence[Candidate], scale: int) -> None:
    """Clear the boxes of ``nearer`` in ``red`` and ``blue``, in place."""
    for c in nearer:
        x0, y0 = c.red_bbox_px[0] // scale, c.red_bbox_px[1] // scale
        x1 = -(-(c.red_bbox_px[0] + c.red_bbox_px[2]) // scale)
        y1 = -(-(c.blue_bbox_px[1] + c.blue_bbox_px[3]) // scale)
        red[max(0, y0) : max(0, y1), max(0, x0) : max(0, x1)] = 0
        blue[max(0, y0) : max(0, y1), max(0, x0) : max(0, x1)] = 0


class NearerCleared:
    """:func:`without_nearer` of a list of nearer candidates that only grows (the structure search's own, nearest
    first): the masks are copied once and each candidate's box cleared once, not every call anew."""

    __slots__ = ("_blue", "_done", "_red", "_scale")

    def __init__(self, red: np.ndarray, blue: np.ndarray, scale: int) -> None:
        self._red, self._blue, self._scale, self._done = red, blue, scale, 0

    def masks(self, nearer: Sequence[Candidate]) -> Tuple[np.ndarray, np.ndarray]:
        """``without_nearer(red, blue, nearer, scale)``; ``nearer`` must extend the list of the call before."""
        if len(nearer) > self._done:
            if not self._done:  # the caller's masks are copied once; later boxes are cleared in the copies
                self._red, self._blue = self._red.copy(), self._blue.copy()
            _clear(self._red, self._blue, nearer[self._done :], self._scale)
            self._done = len(nearer)
        return self._red, self._blue


def occluded_sides(cands: List[Candidate], scale: int) -> List[Candidate]:
    """Mark the side of a narrower-than-whole candidate where a nearer landmark (larger white body)
    stands right beside it: that landmark hides it there, so that side is no limb."""
    out = []
    for c in cands:
        x0, x1 = c.red_bbox_px[0], c.red_bbox_px[0] + c.red_bbox_px[2]
        near_l = near_r = False
        if c.visible < 0.9:
            for o in cands:
                if o.white_px <= c.white_px:
                    continue
                ox0, ox1 = o.red_bbox_px[0], o.red_bbox_px[0] + o.red_bbox_px[2]
                near_l = near_l or abs(ox1 - x0) <= 2 * scale
                near_r = near_r or abs(ox0 - x1) <= 2 * scale
        left, right = (near_l, near_r) if not (c.cut_left or c.cut_right) else (c.cut_left, c.cut_right)
        # the side a nearer landmark hides, even where the run's other end was marked cut too (its band runs on
        # into a same-coloured wall): that end may still be a limb (.limbs.measure_columns)
        occluded = "left" if near_l and not near_r else "right" if near_r and not near_l else ""
        if (left, right, occluded) != (c.cut_left, c.cut_right, c.occluded):
            c = dataclasses.replace(c, cut_left=left, cut_right=right, occluded=occluded)
        out.append(c)
    return out
