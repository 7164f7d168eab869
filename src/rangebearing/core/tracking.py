"""Tracking: between full-frame scans, measure last frame's landmarks where they should be.

A track is a landmark's two bands from the previous frame and their image
velocity. The next frame is searched only in each band's box, moved by that
velocity and grown by a motion margin; no thresholding of the frame, no region
search, no pairing, just the batched sub-pixel measurement. A track survives
when both bands are found with about the same weight (area) as before and still
in the landmark's geometry; otherwise it is lost and the caller scans the whole
frame next.

Near the frame's edge the moments of what is left lag the landmark (they move
by about half its motion while it runs out), so there the band's columns are
measured afresh (:func:`edge_run`): its box then ends at the frame's edge, which
makes it cut on that side (:func:`.limbs.cut_sides`), and ``visible`` is the
share of it still in the frame, as a full scan would have it.
"""

from __future__ import annotations

import dataclasses
from typing import List, Optional, Sequence, Tuple

import numpy as np

from .._compat import frozen
from .color import Gains
from .detect import BandCentroids, combine
from .edges import excess, limb, linear_table
from .limbs import FRAME_EDGE_PX, _tile, thin_step
from .measure import measure_rows_all
from .pairing import PairingLimits
from .params import DetectionParams
from .refine import BandFix, Margin, measure_bands
from .structure import MIN_VISIBLE, Candidate
from .types import XY, BBox, LandmarkGeometry

MASS_RATIO = (0.6, 1.6)  # a band's weight may change this much between frames


@frozen
class Track:
    """A landmark followed from frame to frame."""

    bands: BandCentroids
    velocity_px: XY = (0.0, 0.0)
    #: the bands' moments (red, blue) measured in the last tracked frame; ``None`` right after a full scan
    moments_px: Optional[Tuple[XY, XY]] = None


def _origin(t: Track) -> BandCentroids:
    """The bands to move the boxes from: at the moments last measured, so a box moves as its moments move.

    A band's row is the mean of its moment and its edges (:func:`.detect.combine`):
    moving the box by the moment's step from that mean would add half their
    difference to the box every frame, and the box would walk off the band.
    """
    if t.moments_px is None:
        return t.bands
    return dataclasses.replace(t.bands, red_xy_px=t.moments_px[0], blue_xy_px=t.moments_px[1])


def _moved(box: BBox, dx: float, dy: float) -> BBox:
    return (round(box[0] + dx), round(box[1] + dy), box[2], box[3])


def motion_margin(box: BBox) -> Margin:
    """How far a band may stray from its predicted box between frames (pixels, x and y)."""
    return (box[2] // 3 + 4, box[3] // 3 + 2)


def search_boxes(track: Track) -> Tuple[BBox, BBox]:
    """The red and blue boxes moved by the track's velocity."""
    vx, vy = track.velocity_px
    return _moved(track.bands.red_bbox_px, vx, vy), _moved(track.bands.blue_bbox_px, vx, vy)


def crossing(tracks: Sequence[Track], slack_px: float = 2.0) -> bool:
    """Whether two landmarks may overlap in the image this frame: their predicted columns meet.

    Each landmark's columns are its bands' boxes moved by its velocity and grown
    by its speed and ``slack_px``. Where two meet, one passes in front of the
    other: windows then hold parts of both (a track slides onto its neighbour or
    measures the merged pair), and the one behind is partly hidden in a way
    that only a full scan measures (or that ends a robot's occlusion). The
    caller scans the whole frame instead.
    """
    if len(tracks) < 2:
        return False
    spans = []
    for t in tracks:
        red, blue = search_boxes(t)
        grow = abs(t.velocity_px[0]) + slack_px
        spans.append((min(red[0], blue[0]) - grow, max(red[0] + red[2], blue[0] + blue[2]) + grow))
    spans.sort()
    ends = np.maximum.accumulate([end for _, end in spans])
    return any(start < end for (start, _), end in zip(spans[1:], ends[:-1]))


def plausible(old: BandCentroids, red: BandFix, blue: BandFix, geometry: LandmarkGeometry, lim: PairingLimits) -> bool:
    """Both bands kept their weight and still stand one above the other at the landmark's spacing."""
    lo, hi = MASS_RATIO
    if not (lo * old.red_mass_px <= red.mass_px <= hi * old.red_mass_px):
        return False
    if not (lo * old.blue_mass_px <= blue.mass_px <= hi * old.blue_mass_px):
        return False
    w = old.width_px
    dy = blue.xy_px[1] - red.xy_px[1]
    expected = w * geometry.band_spacing_m / geometry.diameter_m
    slack = lim.slack_px / expected
    if not lim.spacing_lo - slack <= dy / expected <= lim.spacing_hi + slack:
        return False
    return abs(blue.xy_px[0] - red.xy_px[0]) <= lim.max_dx * w + lim.slack_px


def advance(old: Track, now: BandCentroids, moments_px: Optional[Tuple[XY, XY]] = None) -> Track:
    """The track after this frame: the new bands, velocity the last step of the centroids."""
    b = old.bands
    rdx, rdy = now.red_xy_px[0] - b.red_xy_px[0], now.red_xy_px[1] - b.red_xy_px[1]
    bdx, bdy = now.blue_xy_px[0] - b.blue_xy_px[0], now.blue_xy_px[1] - b.blue_xy_px[1]
    return Track(now, (0.5 * (rdx + bdx), 0.5 * (rdy + bdy)), moments_px)


def _moved_bands(old: BandCentroids, red: BandFix, blue: BandFix) -> Tuple[BBox, BBox]:
    """The old band boxes moved as the moments moved."""
    rdx, rdy = red.xy_px[0] - old.red_xy_px[0], red.xy_px[1] - old.red_xy_px[1]
    bdx, bdy = blue.xy_px[0] - old.blue_xy_px[0], blue.xy_px[1] - old.blue_xy_px[1]
    return _moved(old.red_bbox_px, rdx, rdy), _moved(old.blue_bbox_px, bdx, bdy)


def remeasure(
    bgr: np.ndarray, old: BandCentroids, red: BandFix, blue: BandFix, gains: Gains, geometry: LandmarkGeometry,
    fy_px: float,
) -> Optional[BandCentroids]:
    """The bands measured as a full scan would: moments plus edges, in boxes that follow the moments."""
    if old.candidate is None:
        return _moved_only(old, red, blue)
    cand = _moved_candidate(bgr, old, red, blue, gains, geometry)
    if cand is None:
        return None
    return combine(bgr, cand, red, blue, gains, geometry, fy_px)  # chroma refs: the ones measure_bands was given


def _moved_only(old: BandCentroids, red: BandFix, blue: BandFix) -> BandCentroids:
    """A track without a structure candidate (the paper's path): the moments moved, nothing re-measured."""
    rb, bb = _moved_bands(old, red, blue)
    return dataclasses.replace(old, red_xy_px=red.xy_px, blue_xy_px=blue.xy_px, red_bbox_px=rb, blue_bbox_px=bb,
                               red_mass_px=red.mass_px, blue_mass_px=blue.mass_px)


def _moved_candidate(
    bgr: np.ndarray, old: BandCentroids, red: BandFix, blue: BandFix, gains: Gains, geometry: LandmarkGeometry
) -> Optional[Candidate]:
    """The old candidate with its boxes moved as the moments moved, re-cut at the frame's edge
    (:func:`edge_run`); ``None`` when too little of it is left in the frame for a full scan to report it."""
    rb, bb = _moved_bands(old, red, blue)
    cand = dataclasses.replace(old.candidate, red_bbox_px=rb, blue_bbox_px=bb)
    mx = motion_margin(rb)[0]
    if rb[0] - mx > FRAME_EDGE_PX and rb[0] + rb[2] + mx < bgr.shape[1] - FRAME_EDGE_PX:
        return cand
    run = edge_run(bgr, cand, red.xy_px[0], gains, geometry)
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
    reach = round(silhouette_px) + motion_margin(c.red_bbox_px)[0]
    y0, y1 = int(ry + 0.2 * rh), int(ry + 0.8 * rh) + 1
    tile, ox, _ = _tile(bgr, rx - reach, y0, rx + rw + reach, y1, row_step=thin_step(y1 - y0))
    n = tile.shape[1]
    if n < 4 or tile.shape[0] == 0:
        return None
    er, _ = excess(tile, gains)
    q = (er / np.maximum(linear_table()[tile].sum(axis=2), 1e-3)).mean(axis=0)
    core = max(0, min(n - 1, round(core_x_px) - ox))
    level = float(np.median(q[max(0, core - 2) : core + 3]))
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


def step(
    bgr: np.ndarray,
    tracks: Sequence[Track],
    cfg: DetectionParams,
    gains: Gains,
    geometry: LandmarkGeometry,
    limits: PairingLimits,
    fy_px: float = 634.0,
) -> Tuple[List[Track], bool]:
    """Follow every track into this frame; returns the surviving tracks and whether any was lost.

    Each followed landmark is measured as :func:`remeasure` does, all of them in
    one batch (:func:`.measure.measure_rows_all`). The bands' chroma references
    are the ones kept from the last full scan: ``measure_bands`` returns them as given.
    """
    boxes: List[BBox] = []
    refs: List[float] = []
    for t in tracks:
        boxes.extend(search_boxes(t))
        refs.extend((t.bands.red_chroma, t.bands.blue_chroma))  # kept from the last full scan
    margins = [motion_margin(b) for b in boxes]
    fixes = measure_bands(bgr, boxes, [True, False] * len(tracks), margins, cfg, gains, refs=refs)
    found = [(t, red, blue) for t, red, blue in zip(tracks, fixes[0::2], fixes[1::2])
             if red is not None and blue is not None and plausible(t.bands, red, blue, geometry, limits)]
    found = _tight(bgr, found, cfg, gains, geometry, limits)
    lost = len(found) < len(tracks)
    cands = [_moved_candidate(bgr, _origin(t), red, blue, gains, geometry) if t.bands.candidate is not None else None
             for t, red, blue in found]
    gone = [k for k, (t, _, _) in enumerate(found) if t.bands.candidate is not None and cands[k] is None]
    if gone:  # ran off the frame: no reading, as a full scan would give none
        lost = True
        found = [f for k, f in enumerate(found) if k not in gone]
        cands = [c for k, c in enumerate(cands) if k not in gone]
    with_cand = [k for k, c in enumerate(cands) if c is not None]
    rows = measure_rows_all(bgr, [cands[k] for k in with_cand], gains, geometry,
                            [0.5 * (found[k][1].xy_px[0] + found[k][2].xy_px[0]) for k in with_cand])
    row_of = dict(zip(with_cand, rows))
    kept: List[Track] = []
    for k, ((t, red, blue), cand) in enumerate(zip(found, cands)):
        if cand is None:
            now: Optional[BandCentroids] = _moved_only(_origin(t), red, blue)
        else:
            now = combine(bgr, cand, red, blue, gains, geometry, fy_px, None, row_of[k])
        if now is None:
            lost = True
            continue
        kept.append(advance(t, now, (red.xy_px, blue.xy_px)))
    return _distinct(kept), lost


def _tight(
    bgr: np.ndarray, found: List[Tuple[Track, BandFix, BandFix]], cfg: DetectionParams, gains: Gains,
    geometry: LandmarkGeometry, limits: PairingLimits,
) -> List[Tuple[Track, BandFix, BandFix]]:
    """The bands measured again in their moved boxes with a full scan's margins (:func:`.detect.refine`).

    The motion margin lets a window take in what lies around the band (the
    robot's chassis, a neighbour's edge): its moments lean towards it, the box
    follows the moments into the next frame, and the lean adds up frame after
    frame until the next full scan. Measured again in the moved box, grown only
    as a full scan grows it, a band is read from the same pixels a full scan reads.
    """
    if not found:
        return found
    m = cfg.downscale + 1
    boxes = [b for t, red, blue in found for b in _moved_bands(_origin(t), red, blue)]
    refs = [r for t, _, _ in found for r in (t.bands.red_chroma, t.bands.blue_chroma)]
    fixes = measure_bands(bgr, boxes, [True, False] * len(found), [(m, m + b[3] // 4) for b in boxes], cfg, gains,
                          refs=refs)
    return [(t, red, blue) for (t, _, _), red, blue in zip(found, fixes[0::2], fixes[1::2])
            if red is not None and blue is not None and plausible(t.bands, red, blue, geometry, limits)]


def _distinct(tracks: List[Track]) -> List[Track]:
    """Drop a track that converged onto an earlier one's landmark (red centroids within half a width)."""
    if len(tracks) < 2:
        return tracks
    xy = np.array([t.bands.red_xy_px for t in tracks])
    near = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
    half_width = 0.5 * np.array([t.bands.width_px for t in tracks])
    dup = np.triu(near < half_width[:, None], k=1).any(axis=0)
    return [t for t, d in zip(tracks, dup) if not d]
