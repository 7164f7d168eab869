"""Band detection in a whole frame: the fast path and the paper's path.

Fast path (default)::

    downscale (area) → grey-world balance → HSV → red/blue hue thresholds
    → median (majority) filter of the masks, sized to keep the farthest band
    → connected regions → pairing → sub-pixel moments on the *unfiltered*
      full-resolution pixels inside each paired band

The filter decides *where* the bands are; the moments of the original pixels decide *exactly
where*: a median over the colour image rounds the band corners and moves the centroids, which costs range accuracy.

Paper path: median filter over the whole colour frame, HSV, thresholds, and
the moments of the whole red and blue masks — one landmark at most.

Between full scans, :mod:`rangebearing.core.tracking` measures known landmarks in place instead.
"""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Sequence, Tuple

import cv2
import numpy as np

from .._compat import frozen
from .arc import arc_scale
from .blobs import mask_centroid
from .color import Gains, apply_gains, class_masks, clipped_mask, hue_mask, relaxed_floors, to_hsv
from .colour_tune import relaxed_hues
from .denoise import Box, band_masks, median_filter, none_apart_filtered
from .gain_clip import pushed_over, reclass_pushed
from .limbs import moments_outline
from .measure import CENTROID_SIGMA_X_PX, cut_sides, measure_columns, measure_rows, measure_rows_all
from .params import DetectionParams
from .refine import BandFix, Pyramid, half_or_area, measure_bands
from .search_image import SearchImage
from .structure import Candidate, Found, search, search_apart
from .types import XY, BBox, LandmarkGeometry, union
from .uncertainty import row_spread_px, silhouette_share


@frozen
class BandCentroids:
    """One landmark's two bands: sub-pixel centroids, boxes and weights (full-resolution pixels)."""

    red_xy_px: XY
    blue_xy_px: XY
    red_bbox_px: BBox
    blue_bbox_px: BBox
    red_mass_px: float
    blue_mass_px: float
    red_chroma: float
    blue_chroma: float
    sigma_l_px: float = 0.0  # one-sigma uncertainty of the band spacing L (full-resolution pixels)
    sigma_x_px: float = 0.0  # ... and of the landmark's image column
    spread_l_px: float = 0.0  # ... of L from its row estimators' disagreement (uncertainty.row_spread_px)
    visible: float = 1.0  # share of the landmark's silhouette seen
    candidate: Optional[Candidate] = None  # what the structure search found (tracking measures it again)
    #: the bands' moments (red, blue) in their boxes, before the edges' rows are combined in (tracking predicts them)
    moments_px: Optional[Tuple[XY, XY]] = None
    #: the colour's own blur (:func:`.uncertainty.chroma_blur_px`) when already measured (tracking keeps a scan's)
    chroma_blur_px: Optional[float] = None

    @property
    def width_px(self) -> float:
        return 0.5 * (self.red_bbox_px[2] + self.blue_bbox_px[2])

    @property
    def bbox_px(self) -> BBox:
        return union(self.red_bbox_px, self.blue_bbox_px)


def downscale(bgr: np.ndarray, s: int) -> np.ndarray:
    """Area-average the frame by ``s`` (trimming to a multiple of ``s``); ``s = 1`` returns it."""
    if s == 1:
        return bgr
    h, w = bgr.shape[:2]
    return cv2.resize(bgr[: h // s * s, : w // s * s], (w // s, h // s), interpolation=half_or_area(s))


def region_masks(small: np.ndarray, cfg: DetectionParams, gains: Gains, ksize: int) -> Tuple[np.ndarray, np.ndarray]:
    """Filtered red and blue masks of a downscaled frame: balance, HSV, thresholds, majority filter."""
    hsv = to_hsv(apply_gains(small, gains))
    red, blue = class_masks(hsv, cfg.red_hue, cfg.blue_hue, cfg.s_min, cfg.v_min, _clipped(small, gains))
    red, blue = reclass_pushed(red, blue, small, gains, pushed_over(small, gains, hsv[..., 2]), cfg.red_hue,
                               cfg.blue_hue, cfg.s_min)
    return band_masks(red, blue, ksize)


def _clipped(small: np.ndarray, gains: Gains) -> Optional[np.ndarray]:
    """Pixels clipped before the gains, when a gain below one may have hidden it (else ``None``)."""
    return clipped_mask(small) if min(gains) < 0.98 else None


SPACING_AGREE = (0.8, 1.25)  # band spacing / (white height · 55/40) of a real landmark
WHITE_AGREE = 1.3  # white height measured / found by the structure search (2 px steps at ½ resolution) ...
# ... give or take one downscaled row: the search counts the blurred rows at both band edges as white and
# the edges measured under blur (defocus, chroma smoothing) thin a small landmark's body, a third of it at 1.6 m
WHITE_SLACK_PX = 2.0


def spacing_agrees(spacing_px: float, white_px: float, geometry: LandmarkGeometry,
                   search_white_px: Optional[float] = None) -> bool:
    """Whether a band spacing and a white body's height (full-resolution pixels) measure one landmark.

    The spacing must lie within ``SPACING_AGREE`` of the spacing the body's height gives
    (``geometry.band_spacing_m`` over the body's 40 mm). On the long side the body may be taken
    taller than measured, up to ``WHITE_SLACK_PX`` more, where the structure search saw it taller
    (``search_white_px``, counted at 1/downscale with the blurred rows at both band edges, less
    those ``WHITE_SLACK_PX``): the bands' colour bled into the body (chroma coded at half
    resolution, lateral colour) moves both inner edges into it, so the edges measure it thin while
    the band centres, found from both edges, keep the spacing (1.0-1.5 m under the photoreal-alt
    camera: search 24-26 px, edges 19-20 px, spacing within 1 % of the truth). A body the two
    measure alike gets no slack: a thing whose spacing is too long for its body stays no landmark.
    """
    if white_px <= 0:
        return False
    k = geometry.band_spacing_m / (geometry.height_m - 2 * geometry.band_height_m)
    seen = white_px if search_white_px is None else search_white_px - WHITE_SLACK_PX
    long_px = min(max(white_px, seen), white_px + WHITE_SLACK_PX)
    return SPACING_AGREE[0] * white_px * k <= spacing_px <= SPACING_AGREE[1] * long_px * k


def search_candidates(
    small: np.ndarray, cfg: DetectionParams, gains: Gains, ksize: int, geometry: LandmarkGeometry,
    relaxed: Optional[Sequence[Box]] = None, hsv_of: Optional[Dict[Gains, SearchImage]] = None,
) -> Found:
    """Landmark candidates in a frame downscaled by ``cfg.downscale``, and whether they explain every
    band-coloured region (:func:`.structure.search`). ``relaxed``: the second look
    (:func:`.balance.second_look`) with lower saturation and value floors (:func:`.color.relaxed_floors`)
    and wider hue ranges (:func:`.colour_tune.relaxed_hues`),
    given the ``(x0, y0, x1, y1)`` boxes (full resolution) of the landmarks already found: it is not
    searched when the masks hold no red or no blue outside them (a landmark apart from them has both),
    judged before the band filter where that is exact (:func:`.denoise.none_apart_filtered`).
    ``hsv_of``: the frame's :class:`.search_image.SearchImage` by gains, kept for the searches after
    (the second look's)."""
    img = None if hsv_of is None else hsv_of.get(gains)
    if img is None:
        img = SearchImage(small, gains)
        if hsv_of is not None:
            hsv_of[gains] = img
    s_min, v_min = (cfg.s_min, cfg.v_min) if relaxed is None else relaxed_floors(cfg.s_min, cfg.v_min)
    red, blue = img.class_masks(cfg if relaxed is None else relaxed_hues(cfg), s_min, v_min)
    if relaxed is not None and none_apart_filtered(red, blue, relaxed, cfg.downscale, ksize):
        return Found([], lambda: True)  # as search_apart says of filtered masks with nothing apart
    red, blue = band_masks(red, blue, ksize)
    min_area = max(2, int(cfg.min_band_px * cfg.min_band_px / (cfg.downscale * cfg.downscale)))
    if relaxed is not None:
        return search_apart(red, blue, img.hsv, cfg.downscale, geometry, cfg.max_landmarks, min_area, relaxed)
    return search(red, blue, img.hsv, cfg.downscale, geometry, cfg.max_landmarks, min_area)


def refine(
    bgr: np.ndarray,
    cands: Sequence[Candidate],
    cfg: DetectionParams,
    gains: Gains,
    geometry: LandmarkGeometry,
    fy_px: float,
    pyramid: Optional[Pyramid] = None,
) -> List[BandCentroids]:
    """Sub-pixel band centres of every candidate; candidates whose bands vanished are dropped.

    Columns come from the saturation-weighted moments of :func:`.refine.measure_bands`
    (all bands in one batch) or, for a landmark cut on one side, from its other
    limb; rows from the bands' edges in linear light (:func:`.measure.measure_rows`).
    """
    if not cands:
        return []
    m = cfg.downscale + 1
    boxes = [b for c in cands for b in (c.red_bbox_px, c.blue_bbox_px)]
    # the boxes come from edges found at 1/downscale: grow them by that and a quarter of the band
    margins = [(m, m + b[3] // 4) for b in boxes]
    fixes = measure_bands(bgr, boxes, [True, False] * len(cands), margins, cfg, gains, pyramid)
    live = [(c, r, b) for c, r, b in zip(cands, fixes[0::2], fixes[1::2]) if r is not None and b is not None]
    rows = measure_rows_all(bgr, [c for c, _, _ in live], gains, geometry,
                            [0.5 * (r.xy_px[0] + b.xy_px[0]) for _, r, b in live])
    found = (combine(bgr, c, r, b, gains, geometry, fy_px, pyramid, rw) for (c, r, b), rw in zip(live, rows))
    return [f for f in found if f is not None]


_MEASURE = object()  # combine's default: measure the rows itself


def combine(
    bgr: np.ndarray,
    c: Candidate,
    red: Optional[BandFix],
    blue: Optional[BandFix],
    gains: Gains,
    geometry: LandmarkGeometry,
    fy_px: float,
    pyramid: Optional[Pyramid] = None,
    rows: Any = _MEASURE,
    sigma_l_px: Optional[float] = None,
    chroma_blur_px: Optional[float] = None,
) -> Optional[BandCentroids]:
    """One candidate's band centres from its moments (``red``, ``blue``) and its edges; ``None`` if a band is gone.

    ``rows``: what :func:`.measure.measure_rows` gives for the candidate at the bands'
    mean column, when the caller measured all candidates' rows at once. ``sigma_l_px``
    (instead of the rows') and ``chroma_blur_px``: values the caller keeps (tracking, a full scan's).
    """
    if red is None or blue is None:
        return None
    moments_x_px = 0.5 * (red.xy_px[0] + blue.xy_px[0])
    if rows is _MEASURE:
        rows = measure_rows(bgr, c, gains, geometry, moments_x_px)
    if rows is None:
        return None
    # the band spacing and the white body's height are two measures of one size: they must agree
    red_y, blue_y = rows.band_y(True, red.xy_px[1]), rows.band_y(False, blue.xy_px[1])
    if not spacing_agrees(blue_y - red_y, rows.white_px, geometry, c.white_px):
        return None
    # ... and the white body measured here must be the one the structure search found at 1/downscale
    if not c.white_px / WHITE_AGREE - WHITE_SLACK_PX <= rows.white_px <= c.white_px * WHITE_AGREE + WHITE_SLACK_PX:
        return None
    cols = measure_columns(bgr, c, gains, geometry, fy_px, rows, pyramid, moments_x_px)
    if cols is None:
        x_r, x_b, sx = red.xy_px[0], blue.xy_px[0], CENTROID_SIGMA_X_PX
        if c.hidden_band:  # a partly hidden band's moments are pulled off the axis: the whole one places both
            x_r = x_b = x_b if c.hidden_band == "red" else x_r
        cx_px = 0.5 * (bgr.shape[1] - 1)
        x_r, x_b = (moments_outline(x, cx_px, fy_px, rows.white_px, geometry) for x in (x_r, x_b))
    else:
        x_r = x_b = cols[0]
        sx = cols[1]
    if any(cut_sides(c, bgr.shape[1])):  # rows read over the columns that show, towards a limb (core/arc.py)
        rx, rw = c.red_bbox_px[0], c.red_bbox_px[2]
        k = arc_scale((rx, rx + rw), 0.5 * (x_r + x_b), 0.5 * (bgr.shape[1] - 1), fy_px, rows.white_px, geometry)
        mid_y = 0.5 * (red_y + blue_y)
        red_y, blue_y = mid_y - k * (mid_y - red_y), mid_y + k * (blue_y - mid_y)
    return BandCentroids(
        (x_r, red_y),
        (x_b, blue_y),
        c.red_bbox_px,
        c.blue_bbox_px,
        red.mass_px,
        blue.mass_px,
        red.chroma_ref,
        blue.chroma_ref,
        sigma_l_px=rows.sigma_l_px if sigma_l_px is None else sigma_l_px,
        sigma_x_px=sx,
        spread_l_px=row_spread_px(red.xy_px[1], rows.red_y_px, rows.red_merged,
                                  blue.xy_px[1], rows.blue_y_px, rows.blue_merged, rows.red_fits, rows.blue_fits),
        visible=silhouette_share(c.visible, c.white_px, rows.white_px, fy_px, geometry),
        candidate=c,
        moments_px=(red.xy_px, blue.xy_px),
        chroma_blur_px=chroma_blur_px,
    )


def detect_paper(bgr: np.ndarray, cfg: DetectionParams) -> List[BandCentroids]:
    """The paper's pipeline as published: median over the colour frame, HSV, whole-mask moments.

    Finds at most one landmark: the centroid of *all* red pixels and of *all*
    blue pixels, so a second landmark or any red/blue object corrupts it.
    """
    hsv = to_hsv(median_filter(bgr, cfg.median_ksize))
    red = mask_centroid(hue_mask(hsv, cfg.red_hue, cfg.s_min, cfg.v_min))
    blue = mask_centroid(hue_mask(hsv, cfg.blue_hue, cfg.s_min, cfg.v_min))
    if red is None or blue is None or blue[1] <= red[1]:
        return []
    side = float(np.sqrt(red[2]))  # the paper has no band boxes: squares of the bands' areas
    boxes = [(int(c[0] - side / 2), int(c[1] - side / 4), int(side), int(side / 2)) for c in (red, blue)]
    return [BandCentroids((red[0], red[1]), (blue[0], blue[1]), boxes[0], boxes[1], red[2], blue[2], 0.0, 0.0)]
