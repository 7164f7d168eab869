"""Columns of a landmark cut on one side, from its other limb.

A landmark seen whole is measured by the saturation-weighted moments of
:mod:`.refine`; one seen narrower than its silhouette though cut nowhere (a side too dim for the
structure search) by its limbs. One cut on a side (a nearer landmark in front, a neighbour
touching it, the frame's edge) is placed from its other limb instead: the
moments of what is left would pull it towards the inside, by up to half a
silhouette. The limb is found on each band's chromaticity profile
(:func:`.edges.limb`), and the outline's centre from it by the tangent rays.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Optional, Tuple

import numpy as np

from .color import Gains
from .edges import excess, linear_table
from .limb_edge import limb
from .refine import Pyramid
from .stats import median
from .structure import Candidate
from .types import LandmarkGeometry

if TYPE_CHECKING:
    from .measure import Rows

CENTROID_SIGMA_X_PX = 0.15  # column centroid of a whole landmark (saturation moments)
LIMB_SIGMA_X_PX = 0.8  # a limb edge on a shaded cylinder side
OUTLINE_ITERATIONS = 4  # fixed-point steps for the axis angle (each gains about two decimal places)
LIMB_AGREE_PX = 1.5  # the two bands' limbs of one cylinder agree within this; farther apart, one was widened
MAX_SAMPLES = 24  # columns (rows) averaged into a row (column) profile
HIDDEN_BELOW = 0.95  # a candidate cut on both sides seen narrower than this share of its silhouette is partly hidden
RUN_END_PX, RUN_END_SHARE = 3.0, 0.1  # a limb this far (px + share of outline) from its run's end: not its own
WHOLE_WIDTH = 0.1  # two limbs this close (relative) to a whole outline apart are both natural
NARROW_AGREE_PX = 2.0  # a narrow one's limbs overrule its moments this far off (~3.5 σ of the two apart)
FRAME_EDGE_PX = 2  # a run starting this close to the frame's edge (½-resolution columns) may be cut by it


def _tile(bgr: np.ndarray, x0: int, y0: int, x1: int, y1: int, col_step: int = 1, row_step: int = 1):
    """The frame's region (clipped), every ``col_step``-th column and ``row_step``-th row, and its origin.

    Profiles are means along one axis, so thinning the other keeps them linear in
    coverage (an area-averaged pyramid averages *encoded* values, which does not).
    """
    h, w = bgr.shape[:2]
    x0, y0, x1, y1 = max(0, x0), max(0, y0), min(w, x1), min(h, y1)
    return bgr[y0:y1:row_step, x0:x1:col_step], x0, y0


def cut_sides(c: Candidate, frame_w_px: int) -> Tuple[bool, bool]:
    """``(left, right)``: sides of the candidate that are no limb of the cylinder.

    Besides what the structure search saw (a nearer landmark, a touching
    neighbour), the frame's own edge cuts a landmark: the moments of what is
    left would place it towards the inside, by up to half a silhouette.
    """
    left, right = at_frame_edges(c, frame_w_px)
    return c.cut_left or left, c.cut_right or right


def at_frame_edges(c: Candidate, frame_w_px: int) -> Tuple[bool, bool]:
    """``(left, right)``: sides of the candidate that touch the frame's edge (within ``FRAME_EDGE_PX``)."""
    rx, _, rw, _ = c.red_bbox_px
    return rx <= FRAME_EDGE_PX, rx + rw >= frame_w_px - FRAME_EDGE_PX


def thin_step(n: int) -> int:
    """Thinning that keeps about MAX_SAMPLES of ``n`` lines."""
    return max(1, n // MAX_SAMPLES)


def measure_columns(
    bgr: np.ndarray,
    c: Candidate,
    gains: Gains,
    geometry: LandmarkGeometry,
    fy_px: float,
    rows: Rows,
    pyramid: Optional[Pyramid] = None,
    moments_x_px: Optional[float] = None,
) -> Optional[Tuple[float, float]]:
    """``(x_px, sigma_x_px)`` of a landmark cut on a side, from a limb; ``None``: keep the moments.

    Cut on exactly one side: placed from its other limb. Both bands' limbs are
    measured (:func:`.edges.limb`); they are one cylinder's outline, so when they
    disagree the inner one wins (a same-coloured band beside it only ever widens a
    band). ``x_px`` is the outline's centre, the column the model expects
    (:func:`.model.axis_bearing` takes it to the axis), placed from the limb by
    :func:`outline_centre`.

    Marked cut on both sides by the structure search and partly hidden (``visible`` below ``HIDDEN_BELOW``):
    the moments of what is left lie off the axis by up to half the hidden part, so
    a limb places it where one side shows one: where only one side falls off to a
    background like a limb (the other runs on into a same-coloured band in front),
    from that one; where both do and they lie a whole outline apart, from their
    midpoint. Where both fall off closer together (something of another colour in
    front on one side) the side is not known: the moments stand. Marked cut nowhere but seen
    narrower than its silhouette (``visible`` below ``HIDDEN_BELOW``: a shaded or glossy side too
    dim for the structure search, which the moments of the run it saw then miss too): the limbs
    place it as for a candidate cut on both sides (the chromaticity they are found on does not
    depend on shading), where they lie more than ``NARROW_AGREE_PX`` from the bands' moments'
    column ``moments_x_px``; closer, the moments, the finer measure, stand. Cut by the frame's
    edge on one side and marked cut by the search on the other (a far landmark's band of its
    colour touching it): that side's limb, where it ends the run the search saw, places it.
    Beside a nearer landmark
    (``occluded``) the side away from it is the limb, whatever the structure search marked
    there. A limb found farther than
    ``RUN_END_PX`` + ``RUN_END_SHARE`` of the outline from the end of the run the structure
    search saw on its side is not taken (a background of the band's colour carried the band on).
    """
    frame_l, frame_r = at_frame_edges(c, bgr.shape[1])
    cut_left, cut_right = c.cut_left or frame_l, c.cut_right or frame_r  # cut_sides, the frame's edges kept
    narrow = not (cut_left or cut_right) and c.visible < HIDDEN_BELOW
    if not (cut_left or cut_right or narrow):
        return None
    rx, _, rw, _ = c.red_bbox_px
    ends = False  # the limb must end the run the structure search saw on its side
    far_at_edge = rx + rw >= bgr.shape[1] - FRAME_EDGE_PX if c.occluded == "left" else rx <= FRAME_EDGE_PX
    if c.occluded and not far_at_edge:
        # a nearer landmark hides one side: the other is the limb, where it ends the run (marked cut there, the
        # run's band met a same-coloured background; a band of the colour that carried it on would not end it)
        ends = c.cut_right if c.occluded == "left" else c.cut_left
        cut_left, cut_right = c.occluded == "left", c.occluded == "right"
    elif not c.occluded and ((frame_l and c.cut_right and not frame_r) or (frame_r and c.cut_left and not frame_l)):
        # the frame's edge cuts one side and the structure search marked the other (a neighbour's band of its
        # colour touching it): that side's limb, where it ends the run the search saw, places it
        ends = True
        cut_left, cut_right = frame_l, frame_r
    if narrow:
        cut_left = cut_right = True
    if cut_left and cut_right and not ((narrow or (c.cut_left and c.cut_right)) and c.visible < HIDDEN_BELOW):
        return None  # whole, or the frame's edge cuts a side: no limb there, none known on the other
    white_m = geometry.height_m - 2 * geometry.band_height_m
    cx_px = 0.5 * (bgr.shape[1] - 1)
    d = fy_px * white_m / max(rows.white_px, 1e-3) + geometry.radius_m
    half = rows.white_px * geometry.radius_m / white_m * (1.0 - geometry.radius_m / d)
    if narrow and (1.0 - c.visible) * half <= NARROW_AGREE_PX:
        return None  # the run's moments lie within half its missing width of the outline's centre: they stand
    both = cut_left and cut_right
    edge_r = _limb_edge(bgr, c, gains, geometry, rows, half, True) if both or not cut_right else None
    edge_l = _limb_edge(bgr, c, gains, geometry, rows, half, False) if both or not cut_left else None
    tol = RUN_END_PX + RUN_END_SHARE * 2 * half
    if both or ends:  # a side's limb, where it has one, ends the run the structure search saw there
        edge_r = edge_r if edge_r is not None and abs(edge_r - (rx + rw)) <= tol else None
        edge_l = edge_l if edge_l is not None and abs(edge_l - rx) <= tol else None
    if edge_r is not None and edge_l is not None:  # both natural: the outline's centre is their midpoint
        if abs((edge_r - edge_l) / max(2 * half, 1e-6) - 1.0) > WHOLE_WIDTH:
            return None
        x = 0.5 * (edge_l + edge_r)
    elif edge_r is not None or edge_l is not None:
        right = edge_r is not None
        x = outline_centre(edge_r if right else edge_l, right, cx_px, fy_px, rows.white_px, geometry)
    else:
        return None
    if not rx - half <= x <= rx + rw + half:  # no limb where the structure said: keep the moments
        return None
    if narrow and (moments_x_px is None or abs(x - moments_x_px) <= NARROW_AGREE_PX):
        return None  # the moments agree with the outline: they are the finer measure
    return x, LIMB_SIGMA_X_PX


def _limb_edge(bgr: np.ndarray, c: Candidate, gains: Gains, geometry: LandmarkGeometry, rows: Rows,
               half: float, right: bool) -> Optional[float]:
    """The column of the candidate's right (``right``) or left limb from both bands' limbs, or ``None``."""
    white_m = geometry.height_m - 2 * geometry.band_height_m
    band_px = rows.white_px * geometry.band_height_m / white_m
    rx, _, rw, _ = c.red_bbox_px
    reach = round(2 * half) + 4
    edges = []
    for y_c, is_red in ((rows.red_y_px, True), (rows.blue_y_px, False)):
        if c.hidden_band == ("red" if is_red else "blue"):  # partly hidden (its robot's mast): its limb may be the mast
            continue
        y0, y1 = int(y_c - 0.3 * band_px), int(y_c + 0.3 * band_px) + 1
        x0, x1 = (rx - 4, rx + rw + reach) if right else (rx - reach, rx + rw + 4)
        tile, ox, _ = _tile(bgr, x0, y0, x1, y1, row_step=thin_step(y1 - y0))
        n = tile.shape[1]
        if n < 4 or tile.shape[0] == 0:  # too narrow, or the band's rows off the frame (cut at its top or bottom)
            continue
        er, eb = excess(tile, gains)
        lin_sum = np.maximum(linear_table()[tile].sum(axis=2), 1e-3)
        ex = er if is_red else eb
        q = (ex / lin_sum).mean(axis=0)  # chromaticity: shading does not move it
        if right:  # start inside, run right
            core = max(0, min(n - 1, int(rx + rw - ox) - int(half)))
        else:
            core = max(0, min(n - 1, int(rx - ox) + int(half)))
        level = median(q[max(0, core - 2) : core + 3])
        mix = (ex.mean(axis=0), lin_sum.mean(axis=0))  # the coverage from the mixture (edges.limb)
        edges.append(ox + limb(q, core, n - 1 if right else 0, level, mix))
    edges = [e for e in edges if math.isfinite(e)]
    if not edges:
        return None
    if len(edges) == 2 and abs(edges[0] - edges[1]) <= LIMB_AGREE_PX:
        return 0.5 * (edges[0] + edges[1])
    # apart: a same-coloured background widened one band (the inner limb is the cylinder's), or a thing in front of
    # one (its robot's mast across the blue band) ended it short of the limb; only the limb ending the run the
    # structure search saw on this side (red over white over blue) can be the cylinder's
    run_end = rx + rw if right else rx
    at_end = [e for e in edges if abs(e - run_end) <= RUN_END_PX + RUN_END_SHARE * 2 * half]
    if len(edges) == 2 and len(at_end) == 1:
        return at_end[0]
    return min(edges) if right else max(edges)


def _half_angle(f_px: float, white_px: float, sec_phi: float, geometry: LandmarkGeometry) -> float:
    """α = asin(r/d): half the angle the cylinder subtends, its axis at range d from the white height
    (``white_px`` on the near surface at depth ``(d − r)·cos φ``; ``sec_phi`` = 1/cos φ)."""
    z_m = f_px * (geometry.height_m - 2 * geometry.band_height_m) / max(white_px, 1e-3)
    return math.asin(min(1.0, geometry.radius_m / (z_m * sec_phi + geometry.radius_m)))


def outline_centre(
    limb_px: float, right: bool, cx_px: float, f_px: float, white_px: float, geometry: LandmarkGeometry
) -> float:
    """Image column of the cylinder's outline centre, from one limb's column.

    The outline spans the tangent rays at ``φ ± α`` (φ the axis's angle to the
    right of the optical axis, α = asin(r/d)), so the other limb lies at
    ``tan(φ_l ∓ 2α)``: off the axis the outline is wider than ``2·f·r/d`` by about
    1/cos²φ, which half a silhouette taken from the white height would miss.
    The range d comes from the white height (measured on the near surface, depth
    ``(d − r)·cos φ``). The principal point is taken at the frame centre and
    fx = fy: an error of a few pixels in either changes the result by hundredths
    of a pixel.
    """
    phi_l = math.atan((limb_px - cx_px) / f_px)
    phi = phi_l
    for _ in range(OUTLINE_ITERATIONS):
        alpha = _half_angle(f_px, white_px, 1.0 / math.cos(phi), geometry)
        phi = phi_l - alpha if right else phi_l + alpha
    other = math.tan(phi - alpha if right else phi + alpha)
    return cx_px + 0.5 * f_px * (math.tan(phi_l) + other)


def moments_outline(x_px: float, cx_px: float, f_px: float, white_px: float, geometry: LandmarkGeometry) -> float:
    """Image column of the outline's centre from the bands' moments' column, off the axis.

    A band's moment weighs each column by the band's height there, which grows as ``1/Z``
    towards the nearer part of the surface; off the optical axis (φ) the depth falls
    across the silhouette, so the moment sits outward of the outline's centre (the column
    :func:`.model.axis_bearing` expects). With ``1/Z`` linear across the outline (half
    width ``α/cos²φ`` in normalised columns, α = asin(r/d)) the shift is
    ``α²·tan φ/(3·cos²φ)`` (to first order in α: at 0.15 m 5 % less): 0.5 px at 0.25 m and 23°,
    0.05 px at 0.8 m. The range d comes from the white height, as in :func:`outline_centre`.
    """
    x_n = (x_px - cx_px) / f_px
    alpha = _half_angle(f_px, white_px, math.hypot(1.0, x_n), geometry)
    return x_px - f_px * alpha * alpha * x_n * (1.0 + x_n * x_n) / 3.0
