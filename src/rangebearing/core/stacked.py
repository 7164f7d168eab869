"""Landmarks that cannot be landmarks because of another one: under it (its robot's body) or inside
the silhouette of a clearly nearer one (made of that one's own parts).

Run after verification on every full scan (:class:`rangebearing.core.pipeline.Pipeline`).
"""

from __future__ import annotations

from typing import List, Sequence

from .detect import BandCentroids
from .types import BBox

STACK_SIZE = 1.25  # a band spacing up to this much larger is still "its size" (measurement scatter)
STACK_REACH = 2.0  # ... and within this many widths of each other across the image
NEST_SIZE = 1.25  # a landmark this much nearer (band spacing) hides whatever lies inside its silhouette ...
NEST_SHARE = 0.5  # ... so a farther one with this share of its box inside that silhouette is part of it


def _share_inside(c: BBox, o: BBox) -> float:
    """The share of box ``c``'s area that lies inside box ``o``."""
    w = min(c[0] + c[2], o[0] + o[2]) - max(c[0], o[0])
    h = min(c[1] + c[3], o[1] + o[3]) - max(c[1], o[1])
    return max(0, w) * max(0, h) / max(1, c[2] * c[3])


def _silhouette(c: BandCentroids, l_px: float, aspect: float, frame_w: float) -> BBox:
    """``c``'s box; cut on one side only, the whole silhouette (``aspect`` × spacing) from its limb on the other."""
    (x, y, w, h), cd, full = c.bbox_px, c.candidate, aspect * l_px
    if cd is None or cd.cut_left == cd.cut_right or w >= full or x <= 0 or x + w >= frame_w - 1:
        return c.bbox_px  # seen whole, cut on both sides, or at the frame's edge: no limb to measure from
    return (x + w - full, y, full, h) if cd.cut_left else (x, y, full, h)


def drop_stacked(found: Sequence[BandCentroids], aspect: float = 35 / 55, frame_w: float = 1e9) -> List[BandCentroids]:
    """Drop every landmark that stands wholly below another of its size or larger, nearby in the image,
    or that lies inside the silhouette of a clearly nearer one.

    Landmarks stand on the floor at about the camera's height, so every one
    spans the horizon's row, a nearer one farther above and below it: one
    whose red band lies below the other's blue band is not a landmark but the
    robot under the upper one read as one (its red top plate, a pale bumper, a
    blue floor in front: a red–white–blue column of the right proportions).

    A nearer landmark hides everything behind it, so nothing farther can be seen inside its silhouette
    (its red top to its blue bottom, its columns; cut on one side, ``aspect`` × its spacing from its limb):
    a small "landmark" there is made of the nearer one's own parts (the top of its red band over its body
    over its robot's camera board in front, or a mast before it, read as a far landmark's red, white, blue).
    """
    # each landmark's spacing, box and width once (properties), then the pairs on plain tuples
    facts = [(c, c.blue_xy_px[1] - c.red_xy_px[1], c.bbox_px, c.width_px) for c in found]
    out = []
    for c, l_c, box_c, w_c in facts:
        below = any(
            o is not c
            and l_c <= STACK_SIZE * l_o
            and c.red_xy_px[1] > o.blue_xy_px[1]
            and abs(c.red_xy_px[0] - o.red_xy_px[0]) <= STACK_REACH * max(w_c, w_o)
            for o, l_o, _, w_o in facts
        )
        inside = any(
            o is not c
            and NEST_SIZE * l_c <= l_o
            and _share_inside(box_c, _silhouette(o, l_o, aspect, frame_w)) >= NEST_SHARE
            for o, l_o, _, _ in facts
        )
        if not (below or inside):
            out.append(c)
    return out
