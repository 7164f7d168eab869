"""Tracking: between full-frame scans, measure last frame's landmarks where they should be.

A track is a landmark's two bands from the previous frame and their image
velocity. The next frame is searched only in each band's box, moved by that
velocity and grown by a motion margin; no thresholding of the frame, no region
search, no pairing, just the batched sub-pixel measurement. A track survives
when both bands are found with about the same weight (area) as before and still
in the landmark's geometry; otherwise it is lost and the caller scans the whole
frame next.

Near the frame's edge a landmark is re-cut there (:mod:`.frame_edge`), as a
full scan would have it.
"""

from __future__ import annotations

import dataclasses
import math
from typing import List, Optional, Sequence, Tuple

import numpy as np

from .._compat import frozen
from .color import Gains
from .detect import BandCentroids, combine
from .frame_edge import near_edge, recut
from .measure import measure_rows_all
from .pairing import PairingLimits
from .params import DetectionParams
from .refine import BandFix, Margin, measure_bands
from .structure import Candidate
from .types import XY, BBox, LandmarkGeometry

MASS_RATIO = (0.6, 1.6)  # a band's weight may change this much between frames
ON_TARGET_PX = 1.5  # a band measured this close to its predicted place was whole inside its tight window


@frozen
class Track:
    """A landmark followed from frame to frame."""

    bands: BandCentroids
    velocity_px: XY = (0.0, 0.0)
    #: the bands' moments (red, blue) measured in the last tracked frame; ``None``: the full scan's (``bands``)
    moments_px: Optional[Tuple[XY, XY]] = None

    @property
    def reach_px(self) -> BBox:
        """The whole landmark's box where it is predicted this frame, grown by the motion margin."""
        red, blue = search_boxes(self)
        x0, y0, x1, y1 = min(red[0], blue[0]), red[1], max(red[0] + red[2], blue[0] + blue[2]), blue[1] + blue[3]
        mx, my = motion_margin(red)
        return (x0 - mx, y0 - my, x1 - x0 + 2 * mx, y1 - y0 + 2 * my)


def _origin(t: Track) -> Tuple[XY, XY]:
    """The (red, blue) points to move the boxes from: the moments last measured, so a box moves as its moments move.

    A band's row comes from its edges, or their mean with its moment (:func:`.measure.Rows.band_y`):
    moving the box by the moment's step from that row would add their difference
    (or half of it) to the box every frame, and the box would walk off the band.
    """
    if t.moments_px is not None:
        return t.moments_px
    b = t.bands
    return b.moments_px if b.moments_px is not None else (b.red_xy_px, b.blue_xy_px)


def _moved(box: BBox, dx: float, dy: float) -> BBox:
    return (round(box[0] + dx), round(box[1] + dy), box[2], box[3])


def motion_margin(box: BBox) -> Margin:
    """How far a band may stray from its predicted box between frames (pixels, x and y)."""
    return (box[2] // 3 + 4, box[3] // 3 + 2)


def search_boxes(track: Track) -> Tuple[BBox, BBox]:
    """The red and blue boxes moved by the track's velocity."""
    vx, vy = track.velocity_px
    return _moved(track.bands.red_bbox_px, vx, vy), _moved(track.bands.blue_bbox_px, vx, vy)


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


def _moved_bands(old: BandCentroids, origin: Tuple[XY, XY], red: BandFix, blue: BandFix) -> Tuple[BBox, BBox]:
    """The old band boxes moved as the moments moved (from ``origin``, :func:`_origin`)."""
    (rx, ry), (bx, by) = origin
    return (_moved(old.red_bbox_px, red.xy_px[0] - rx, red.xy_px[1] - ry),
            _moved(old.blue_bbox_px, blue.xy_px[0] - bx, blue.xy_px[1] - by))


def _moved_only(old: BandCentroids, origin: Tuple[XY, XY], red: BandFix, blue: BandFix) -> BandCentroids:
    """A track without a structure candidate (the paper's path): the moments moved, nothing re-measured."""
    rb, bb = _moved_bands(old, origin, red, blue)
    return dataclasses.replace(old, red_xy_px=red.xy_px, blue_xy_px=blue.xy_px, red_bbox_px=rb, blue_bbox_px=bb,
                               red_mass_px=red.mass_px, blue_mass_px=blue.mass_px)


def _moved_candidate(
    bgr: np.ndarray, old: BandCentroids, origin: Tuple[XY, XY], red: BandFix, blue: BandFix, gains: Gains,
    geometry: LandmarkGeometry,
) -> Optional[Candidate]:
    """The old candidate with its boxes moved as the moments moved, re-cut at the frame's edge
    (:func:`.frame_edge.recut`); ``None`` when too little of it is left in the frame for a full scan to report it."""
    rb, bb = _moved_bands(old, origin, red, blue)
    cand = dataclasses.replace(old.candidate, red_bbox_px=rb, blue_bbox_px=bb)
    if not near_edge(rb, motion_margin(rb)[0], bgr.shape[1]):
        return cand
    return recut(bgr, cand, red.xy_px[0], gains, geometry)


def step(
    bgr: np.ndarray,
    tracks: Sequence[Track],
    cfg: DetectionParams,
    gains: Gains,
    geometry: LandmarkGeometry,
    limits: PairingLimits,
    fy_px: float = 634.0,
) -> Tuple[List[Track], List[Track]]:
    """Follow every track into this frame; returns the surviving tracks and those lost (the caller scans
    the whole frame next).

    Each band is measured first in its predicted box with a full scan's margins
    (:func:`_predicted`); a track whose bands are not where it predicted is looked
    for again in a window grown by the motion margin and then measured as
    :func:`_tight` does (that window may hold a background of the band's colour,
    so only the tight measurement must keep the band's weight). Each followed landmark is then measured as
    :func:`remeasure` does, all of them in one batch
    (:func:`.measure.measure_rows_all`). The bands' chroma references are the
    ones kept from the last full scan: ``measure_bands`` returns them as given.
    """
    found, astray = _predicted(bgr, tracks, cfg, gains, geometry, limits)
    if astray:
        boxes = [b for t in astray for b in search_boxes(t)]
        refs = [r for t in astray for r in (t.bands.red_chroma, t.bands.blue_chroma)]
        fixes = measure_bands(bgr, boxes, [True, False] * len(astray), [motion_margin(b) for b in boxes], cfg, gains,
                              refs=refs)
        wide = [(t, red, blue) for t, red, blue in zip(astray, fixes[0::2], fixes[1::2])
                if red is not None and blue is not None]
        found = found + _tight(bgr, wide, cfg, gains, geometry, limits)
        order = {id(t): k for k, t in enumerate(tracks)}
        found.sort(key=lambda f: order[id(f[0])])  # track order: _distinct keeps the earlier of two
    cands = [_moved_candidate(bgr, t.bands, _origin(t), red, blue, gains, geometry)
             if t.bands.candidate is not None else None
             for t, red, blue in found]
    gone = [k for k, (t, _, _) in enumerate(found) if t.bands.candidate is not None and cands[k] is None]
    if gone:  # ran off the frame: no reading, as a full scan would give none
        found = [f for k, f in enumerate(found) if k not in gone]
        cands = [c for k, c in enumerate(cands) if k not in gone]
    with_cand = [k for k, c in enumerate(cands) if c is not None]
    # the edges' noise (sigma_l_px) is not measured again: it is the last full scan's (see _noise)
    rows = measure_rows_all(bgr, [cands[k] for k in with_cand], gains, geometry,
                            [0.5 * (found[k][1].xy_px[0] + found[k][2].xy_px[0]) for k in with_cand], False)
    row_of = dict(zip(with_cand, rows))
    kept: List[Track] = []
    followed = set()
    for k, ((t, red, blue), cand) in enumerate(zip(found, cands)):
        if cand is None:
            now: Optional[BandCentroids] = _moved_only(t.bands, _origin(t), red, blue)
        else:
            # the colour's blur is the camera's, as the last full scan saw it
            now = combine(bgr, cand, red, blue, gains, geometry, fy_px, None, row_of[k], _noise(t.bands, cand),
                          t.bands.chroma_blur_px)
        if now is None:
            continue
        kept.append(advance(t, now, (red.xy_px, blue.xy_px)))
        followed.add(id(t))
    return _distinct(kept), [t for t in tracks if id(t) not in followed]


def _noise(before: BandCentroids, now: Candidate) -> float:
    """The edges' noise (``sigma_l_px``) of ``before``, for the width the landmark has ``now``.

    The scatter of the per-column edges is the landmark's own pixel noise over its
    columns: it changes as slowly as its size does, so a full scan measures it and
    the tracked frames after it keep it, scaled as the standard error of a mean over
    the columns (1/√width). Tracked frames skip its per-band fit.
    """
    width_px = 0.5 * (now.red_bbox_px[2] + now.blue_bbox_px[2])
    return before.sigma_l_px * math.sqrt(before.width_px / max(width_px, 1e-6))


def _tight_margins(boxes: Sequence[BBox], cfg: DetectionParams) -> List[Margin]:
    """A full scan's margins (:func:`.detect.refine`) around each band box."""
    m = cfg.downscale + 1
    return [(m, m + b[3] // 4) for b in boxes]


def _predicted(
    bgr: np.ndarray, tracks: Sequence[Track], cfg: DetectionParams, gains: Gains, geometry: LandmarkGeometry,
    limits: PairingLimits,
) -> Tuple[List[Tuple[Track, BandFix, BandFix]], List[Track]]:
    """Each track's bands measured in their predicted boxes with a full scan's margins, kept where the
    moments came out within ``ON_TARGET_PX`` of the prediction; the rest (astray) are returned apart.

    A band that lies where its track predicted sits whole inside a window grown
    only by a full scan's margins, so it is measured in one pass from the same
    pixels a full scan reads; one that strayed may be cut by that window, and is
    looked for again in a wider one.
    """
    if not tracks:
        return [], []
    boxes = [b for t in tracks for b in search_boxes(t)]
    refs = [r for t in tracks for r in (t.bands.red_chroma, t.bands.blue_chroma)]
    fixes = measure_bands(bgr, boxes, [True, False] * len(tracks), _tight_margins(boxes, cfg), cfg, gains, refs=refs)
    found, astray = [], []
    for t, red, blue in zip(tracks, fixes[0::2], fixes[1::2]):
        if (red is not None and blue is not None and _on_target(t, red, blue)
                and plausible(t.bands, red, blue, geometry, limits)):
            found.append((t, red, blue))
        else:
            astray.append(t)
    return found, astray


def _on_target(t: Track, red: BandFix, blue: BandFix) -> bool:
    """Both bands' moments within ``ON_TARGET_PX`` of where the track's velocity put them."""
    (rx, ry), (bx, by) = _origin(t)
    vx, vy = t.velocity_px
    return (abs(red.xy_px[0] - rx - vx) <= ON_TARGET_PX and abs(red.xy_px[1] - ry - vy) <= ON_TARGET_PX
            and abs(blue.xy_px[0] - bx - vx) <= ON_TARGET_PX and abs(blue.xy_px[1] - by - vy) <= ON_TARGET_PX)


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
    boxes = [b for t, red, blue in found for b in _moved_bands(t.bands, _origin(t), red, blue)]
    refs = [r for t, _, _ in found for r in (t.bands.red_chroma, t.bands.blue_chroma)]
    fixes = measure_bands(bgr, boxes, [True, False] * len(found), _tight_margins(boxes, cfg), cfg, gains, refs=refs)
    return [(t, red, blue) for (t, _, _), red, blue in zip(found, fixes[0::2], fixes[1::2])
            if red is not None and blue is not None and plausible(t.bands, red, blue, geometry, limits)]


def _distinct(tracks: List[Track]) -> List[Track]:
    """Drop a track that converged onto an earlier one's landmark (red centroids within half a width)."""
    if len(tracks) < 2:
        return tracks
    # (Python floats: ten tracks are 45 pairs, fewer operations than numpy calls on a 10x10 array)
    xy = [t.bands.red_xy_px for t in tracks]
    half_width = [0.5 * t.bands.width_px for t in tracks]
    return [t for j, t in enumerate(tracks)
            if not any(math.hypot(xy[i][0] - xy[j][0], xy[i][1] - xy[j][1]) < half_width[i] for i in range(j))]
