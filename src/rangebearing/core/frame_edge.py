"""A followed landmark at the frame's edge: cut there, as a full scan would have it.

Near the frame's edge the moments of what is left lag the landmark (they move
by about half its motion while it runs out or comes in), so there the band's
columns are measured afresh (:func:`edge_run`): its box then ends at the
frame's edge, which makes it cut on that side (:func:`.limbs.cut_sides`), and
``visible`` is the share of it still in the frame.
"""

from __future__ import annotations

import dataclasses
from typing import Optional, Tuple

import numpy as np

from .color import Gains
from .edges import excess, linear_table
from .limb_edge import limb
from .limbs import FRAME_EDGE_PX, _tile, thin_step
from .stats import median
from .structure import MIN_VISIBLE, Candidate
from .types import BBox, LandmarkGeometry


def near_edge(box: BBox, reach_px: int, frame_w_px: int) -> bool:
    """Whether a band box grown by ``reach_px`` comes within ``FRAME_EDGE_PX`` of the frame's side."""
    return not (box[0] - reach_px > FRAME_EDGE_PX and box[0] + box[2] + reach_px < frame_w_px - FRAME_EDGE_PX)


def recut(
    bgr: np.ndarray, cand: Candidate, core_x_px: float, gains: Gains, geometry: LandmarkGeometry
) -> Optional[Candidate]:
    """A moved candidate near the frame's edge with its boxes re-cut at it (:func:`edge_run`); ``None`` when
    too little of it is left in the frame for a full scan to report it."""
    rb, bb = cand.red_bbox_px, cand.blue_bbox_px
    run = edge_run(bgr, cand, core_x_px, gains, geometry)
    if run is None:  # near the edge, not at it: the boxes only kept inside the frame
        w = bgr.shape[1]
        return dataclasses.replace(cand, red_bbox_px=_clipped(rb, w), blue_bbox_px=_clipped(bb, w))
    x0, x1, visible = run
    if visible < MIN_VISIBLE:
        return None
    return dataclasses.replace(cand, red_bbox_px=(x0, rb[1], x1 - x0, rb[3]), blue_bbox_px=(x0, bb[1], x1 - x0, bb[3]),
                               visible=visible)


def _clipped(box: BBox, frame_w_px: int) -> BBox:
    x0, x1 = max(0, box[0]), min(frame_w_px, box[0] + box[2])
    return (x0, box[1], max(1, x1 - x0), box[3])


def edge_run(
    bgr: np.ndarray, c: Candidate, core_x_px: float, gains: Gains, geometry: LandmarkGeometry
) -> Optional[Tuple[int, int, float]]:
    """``(x0, x1, visible)``: the red band's columns in this frame (end exclusive) and their share of the
    silhouette, for a landmark that may run off the frame's edge; ``None`` when no side reaches the edge.

    The band's chromaticity profile (as :func:`.limbs.measure_columns` takes it) is
    followed from ``core_x_px`` (inside the band: its moments) out to each limb
    (:func:`.edges.limb`); a side that never falls to half the band's level before
    the frame ends is cut by the edge. A side that falls nowhere short of the
    frame's edge keeps the candidate's box.
    """
    _h, w = bgr.shape[:2]
    rx, ry, rw, rh = c.red_bbox_px
    silhouette_px = c.white_px * geometry.diameter_m / (geometry.height_m - 2 * geometry.band_height_m)
    reach = round(silhouette_px) + c.red_bbox_px[2] // 3 + 4  # tracking.motion_margin
    y0, y1 = int(ry + 0.2 * rh), int(ry + 0.8 * rh) + 1
    tile, ox, _ = _tile(bgr, rx - reach, y0, rx + rw + reach, y1, row_step=thin_step(y1 - y0))
    n = tile.shape[1]
    if n < 4 or tile.shape[0] == 0:
        return None
    er, _ = excess(tile, gains)
    q = (er / np.maximum(linear_table()[tile].sum(axis=2), 1e-3)).mean(axis=0)
    core = max(0, min(n - 1, round(core_x_px) - ox))
    level = median(q[max(0, core - 2) : core + 3])
    left, right = limb(q, core, 0, level), limb(q, core, n - 1, level)
    at_left = ox == 0 and not np.isfinite(left)
    at_right = ox + n == w and not np.isfinite(right)
    if not (at_left or at_right):
        return None
    x0 = 0 if at_left else round(ox + left) if np.isfinite(left) else max(0, rx)
    x1 = w if at_right else round(ox + right) + 1 if np.isfinite(right) else min(w, rx + rw)
    if x1 - x0 < 2:
        return None
    return x0, x1, min(1.0, (x1 - x0 + 1) / silhouette_px)
