"""Landmark candidates from the landmark's vertical structure, not from two isolated blobs.

Down every image column a landmark reads red → white → blue: a red run, a white run, a blue run, with the
white run's height ``h`` fixing the rest of the shape (bands ``h·15/40`` tall, the cylinder ``h·35/40`` wide).
The inner red/white and white/blue edges stay sharp and local when a band's *outer* edge merges with a
background of its colour (a red box above it, a blue mat below), and a red box behind the band or a
neighbour's band beside it makes no such column. So:

1. pair red and blue regions that could hold one landmark (overlapping columns, blue starting below red),
   at most ``MAX_REGIONS`` of each colour;
2. in each pair's window, find per column the red-bottom edge ``y1``, blue-top ``y2``, white between;
3. cut the columns into runs whose edges are continuous: a landmark in front of another has other edges,
   so each keeps its own columns;
4. check each run against the cylinder's silhouette (``n`` columns ≈ ``h·35/40``): a run ``k``
   silhouettes wide with band-shaped runs is ``k`` landmarks side by side at one range, split evenly; a
   narrower run is a partly hidden landmark (``visible`` < 1), a much wider one is no landmark;
5. and its bands against its body (each 15/40 of it; what hides part of one leaves the other whole):
   both far thinner (``THIN_BANDS``, neither merged) are another thing's stripes (a flag, a cup on a box).

All coordinates here are in the downscaled masks' pixels until
:func:`search` converts them to full-resolution pixels.
"""

from __future__ import annotations

import functools
from typing import Callable, List, NamedTuple, Optional, Sequence, Tuple

import numpy as np

from .._compat import frozen
from .behind import NearerCleared, occluded_sides
from .color import RELAXED_WHITE_V
from .columns import WHITE_S_MAX, WHITE_V_MIN, bridge, column_edges, runs, window_runs  # noqa: F401  (the column scan lives there)
from .denoise import both_outside
from .fragments import MIN_PIECE, Fragment, extend_along_bands, join_fragments, lit_like_bands, split_runs
from .regions import MAX_REGIONS, band_regions, outside, partnered, region_stats  # noqa: F401  (region cap there)
from .types import BBox, LandmarkGeometry

MAX_PAIRS_PER_LANDMARK = 4  # region pairs examined per landmark wanted
MERGED = 1.7  # a band run longer than this many expected band heights is merged with something
SPLIT_TOL = 0.3  # how far from a whole number of silhouettes a wide run may be and still be split
EXTEND_BELOW = 1.0  # narrower runs than this share of a silhouette are extended along their bands when they run on
MIN_VISIBLE = 0.5  # narrower runs than this share of a silhouette are not reported (findable: 60 %)
# both bands' runs under this share of the 15/40 band height (less half a mask row; real: 0.33 at least)
THIN_BANDS, THIN_SLACK = 0.35, 0.5


@frozen
class Candidate:
    """One landmark hypothesis, in full-resolution pixels.

    ``red_bbox_px``/``blue_bbox_px`` are the expected band boxes (columns of
    the landmark's run, rows from its inner edges and white height).
    ``red_merged``/``blue_merged``: the band's colour runs on past its outer
    edge (a same-coloured background). ``cut_left``/``cut_right``: the run
    ends at something other than the cylinder's limb (a nearer landmark, a
    neighbour, a same-coloured background). ``visible`` is the run's width over
    the silhouette's, at most 1 (for a run extended along its bands, the share of
    the silhouette's area seen).
    """

    red_bbox_px: BBox
    blue_bbox_px: BBox
    white_px: float
    red_merged: bool
    blue_merged: bool
    cut_left: bool
    cut_right: bool
    visible: float
    hidden_band: str = ""  # "red"/"blue": seen in fewer of the columns (partly hidden), its moments no column cue
    body_cols_px: Optional[Tuple[int, int]] = None  # [x0, x1) where the white body shows, when only part of it does
    occluded: str = ""  # "left"/"right": a nearer landmark stands right beside it there and hides that side
    # (left, right): a band ends there, though the other runs on, and no pale thing runs on beside the body
    band_ends: Tuple[bool, bool] = (False, False)


def one_run(a: Candidate, b: Candidate) -> bool:
    """Whether ``a`` and ``b`` share band rows and white body: pieces of one run split into silhouettes
    (or one landmark found twice)."""
    return (a.white_px == b.white_px and a.red_bbox_px[1::2] == b.red_bbox_px[1::2]
            and a.blue_bbox_px[1::2] == b.blue_bbox_px[1::2])


def _pairable(reds: np.ndarray, blues: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(len(reds), len(blues)) arrays: the pairs :func:`region_pairs` examines (band-shaped or
    merged), the columns each pair shares and whether it is the merged kind."""
    rx0, ry0, rw, rh = (reds[:, k, None] for k in (1, 2, 3, 4))
    bx0, by0, bw, bh = (blues[None, :, k] for k in (1, 2, 3, 4))
    overlap = np.minimum(rx0 + rw, bx0 + bw) - np.maximum(rx0, bx0)
    gap = by0 - (ry0 + rh)
    # a white body is 40/35 of the silhouette wide; a partly hidden one (30 % seen) shows less width
    near = (overlap >= 2) & (gap <= 4 * np.minimum(rw, bw) + 3)
    shaped = by0 + bh > ry0 + rh
    merged = ~shaped & (by0 + bh > ry0 + 2)
    return near & (shaped | merged), overlap, merged


def region_pairs(reds: np.ndarray, blues: np.ndarray, max_pairs: int) -> List[Tuple[int, int]]:
    """Row indices of red and blue regions that may hold one landmark: shared columns, blue
    starting no farther below red's bottom than a white body could be.

    Band-shaped regions have blue reaching below red's bottom (blue may start above red when
    it merged with a blue wall behind). A band merged with a same-coloured thing that reaches
    lower (a red box, poster or floor mat beside or under it) has a region whose box ends below
    the blue band's: such pairs are kept too when red starts above blue's bottom, and examined
    after the band-shaped ones, widest shared columns first within each kind.
    """
    if len(reds) == 0 or len(blues) == 0:
        return []
    ok, overlap, merged = _pairable(reds, blues)
    i, j = np.nonzero(ok)
    order = np.lexsort((-overlap[i, j], merged[i, j]))[:max_pairs]
    return list(zip(i[order].tolist(), j[order].tolist()))


def _continues(mask: np.ndarray, rows: Tuple[int, int], col: int) -> bool:
    """Whether ``mask`` is mostly set in ``rows`` of column ``col`` (outside the image: no)."""
    if col < 0 or col >= mask.shape[1]:
        return False
    seg = mask[max(0, rows[0]) : max(0, rows[1]), col]
    return seg.size > 0 and 255 * np.count_nonzero(seg) > 127 * seg.size  # mean > 127 of a 0/255 mask


def _white_on(hsv: np.ndarray, rows: Tuple[int, int], col: int, v_min: int) -> bool:
    """Whether the white body's class (S < ``WHITE_S_MAX``, V ≥ ``v_min``) mostly fills ``rows`` of column
    ``col`` of ``hsv``: a pale thing (a skirting board) runs on beside the body; outside the image: no."""
    if col < 0 or col >= hsv.shape[1]:
        return False
    seg = hsv[max(0, rows[0]) : max(0, rows[1]), col : col + 1].reshape(-1, 3)  # two slices: the YUV path's view
    return seg.size > 0 and 2 * int(np.count_nonzero((seg[:, 1] < WHITE_S_MAX) & (seg[:, 2] >= v_min))) > len(seg)


def search(
    red: np.ndarray,
    blue: np.ndarray,
    hsv: np.ndarray,
    scale: int,
    geometry: LandmarkGeometry,
    max_landmarks: int,
    min_area: int = 2,
    white_v_min: int = WHITE_V_MIN,
    apart: Sequence[Tuple[int, int, int, int]] = (),
) -> Found:
    """Landmark candidates in downscaled red/blue masks (0/255) and their HSV image.

    Returns at most ``max_landmarks`` candidates in full-resolution pixels,
    the nearest (tallest white body) first: a structure whose red band shares most
    of a nearer one's is part of it (edge noise inside its band). The work is bounded: at most
    ``MAX_REGIONS`` regions of each colour and ``MAX_PAIRS_PER_LANDMARK`` region
    pairs per landmark wanted are examined, whatever the frame holds.

    With them, ``explained()``: whether they explain every red and blue region of
    the masks (:func:`explained`, judged only when asked). ``white_v_min``: the white
    body's least V (:func:`.columns.window_runs`). ``apart``: ``(x0, y0, x1, y1)`` boxes (full
    resolution) of landmarks found already; regions that lie within one are not paired
    (:func:`.regions.outside`; the second look of :mod:`.balance` wants landmarks apart from them).
    """
    reds, blues = band_regions(red, blue, min_area)
    if apart:
        reds, blues = outside(reds, apart, scale), outside(blues, apart, scale)
    found = _candidates(reds, blues, red, blue, hsv, scale, geometry, max_landmarks, white_v_min)
    return Found(found, functools.partial(explained, reds, blues, found, scale))


def search_apart(
    red: np.ndarray, blue: np.ndarray, hsv: np.ndarray, scale: int, geometry: LandmarkGeometry,
    max_landmarks: int, min_area: int, apart: Sequence[Tuple[int, int, int, int]],
) -> Found:
    """The second look's :func:`search` (:func:`.balance.second_look`), in masks made at the lower colour
    floors: the white body down to ``RELAXED_WHITE_V``, regions within the ``apart`` boxes not paired; not
    searched at all when either mask holds nothing outside them (a landmark apart from them has both bands)."""
    if not both_outside(red, blue, apart, scale):
        return Found([], lambda: True)  # nothing to find: nothing unexplained
    return search(red, blue, hsv, scale, geometry, max_landmarks, min_area, RELAXED_WHITE_V, apart)


class Found(NamedTuple):
    """A structure search's candidates and ``explained()``: whether they explain all it saw."""

    candidates: List[Candidate]
    explained: Callable[[], bool]


EXPLAIN_MARGIN = 0.25  # a region within this share of a band box's size (and 2 mask pixels) beyond it is that band's


def explained(reds: np.ndarray, blues: np.ndarray, found: Sequence[Candidate], scale: int) -> bool:
    """Whether every red and blue region (:func:`region_stats` rows, mask pixels) lies within a band box of
    its colour of some candidate (full-resolution pixels), grown by ``EXPLAIN_MARGIN`` and 2 mask pixels.

    A region no candidate explains is something else of a band's colour, or a band the search did not
    make into a landmark (its white body not white under these gains, a smaller piece of it found, a
    neighbour merged with it): a search under another balance may find more there.
    """
    for regions, boxes in ((reds, [c.red_bbox_px for c in found]), (blues, [c.blue_bbox_px for c in found])):
        if not len(regions):
            continue
        if not boxes:
            return False
        b = np.asarray(boxes, np.float64) / scale
        mx = np.maximum(2.0, EXPLAIN_MARGIN * b[:, 2])
        my = np.maximum(2.0, EXPLAIN_MARGIN * b[:, 3])
        x0, y0, x1, y1 = b[:, 0] - mx, b[:, 1] - my, b[:, 0] + b[:, 2] + mx, b[:, 1] + b[:, 3] + my
        rx0, ry0 = regions[:, 1, None], regions[:, 2, None]
        rx1, ry1 = rx0 + regions[:, 3, None], ry0 + regions[:, 4, None]
        inside = (rx0 >= x0) & (ry0 >= y0) & (rx1 <= x1) & (ry1 <= y1)
        if not inside.any(axis=1).all():
            return False
    return True


def _candidates(reds: np.ndarray, blues: np.ndarray, red: np.ndarray, blue: np.ndarray, hsv: np.ndarray, scale: int,
                geometry: LandmarkGeometry, max_landmarks: int, white_v_min: int = WHITE_V_MIN) -> List[Candidate]:
    """:func:`search` from the masks' regions (:func:`band_regions` of ``red`` and ``blue``)."""
    white_h = geometry.height_m - 2 * geometry.band_height_m
    band_k, width_k = geometry.band_height_m / white_h, geometry.diameter_m / white_h
    out: List[Candidate] = []
    cleared = NearerCleared(red, blue, scale)  # the masks without the nearer candidates found so far (out)
    taken: List[BBox] = []
    pairs = region_pairs(reds, blues, MAX_PAIRS_PER_LANDMARK * max_landmarks)
    wins = [
        (int(reds[i, 2]), int(blues[j, 2] + blues[j, 4]), int(max(reds[i, 1], blues[j, 1])),
         int(min(reds[i, 1] + reds[i, 3], blues[j, 1] + blues[j, 3])))
        for i, j in pairs
    ]
    split = functools.partial(split_runs, band_k=band_k, width_k=width_k, merged_k=MERGED)
    frags: List[Fragment] = [
        (float(x0 + s0), float(x0 + s1), med_1 + y0, med_2 + y0, gap, med_r, med_b)
        for (y0, _, x0, _), found in zip(wins, window_runs(red, blue, hsv, wins, split, white_v_min))
        for s0, s1, gap, med_r, med_b, med_1, med_2 in found
        if s1 - s0 >= MIN_PIECE  # a column of edge noise neither makes nor joins a landmark
    ]
    frags = list(dict.fromkeys(frags))  # one structure is often found whole in several windows
    # nearest (tallest white body) first: a speck of edge noise inside a landmark's band must not take its place
    for frag in sorted(join_fragments(frags, red, blue, band_k, width_k), key=lambda f: -f[4]):
        c0f, c1f, ey1, ey2, gap, med_r, med_b = frag
        if gap < 2:  # bridged or smoothed below the thinnest white body
            continue
        hb, w_exp = band_k * gap, width_k * gap
        red_merged = med_r > MERGED * hb + 1
        blue_merged = med_b > MERGED * hb + 1
        if not (red_merged or blue_merged) and max(med_r, med_b) + THIN_SLACK < THIN_BANDS * hb:
            continue  # bands far thinner than its body: stripes of another thing (step 5)
        seen, hidden, ext_l, ext_r = 1.0, "", False, False
        if (c1f - c0f) / w_exp < EXTEND_BELOW and not (red_merged or blue_merged):  # a body hidden, bands whole
            # its bands end where a nearer landmark found already hides them (core/behind.py)
            r_m, b_m = cleared.masks(out)
            c0f, c1f, seen, hidden, ext_l, ext_r = extend_along_bands(frag, r_m, b_m, band_k, width_k)
        s0, s1 = int(c0f), int(c1f)
        n = s1 - s0
        ratio = n / w_exp
        k = round(ratio)
        if ratio > 1 + SPLIT_TOL:
            if red_merged or blue_merged:
                continue
            if 1 + MIN_VISIBLE <= ratio < 2 - SPLIT_TOL:  # one whole in front of another shown in part: a
                pieces = [(float(s0), s0 + w_exp), (s1 - w_exp, float(s1))]  # silhouette from each end's limb
            elif k < 2 or abs(ratio - k) > SPLIT_TOL:
                continue
            else:
                pieces = [(s0 + n * q / k, s0 + n * (q + 1) / k) for q in range(k)]
        elif ratio < MIN_VISIBLE or n < 2:
            continue
        else:
            pieces = [(float(s0), float(s1))]
        rrows = (round(ey1 - hb + 1), int(ey1) + 1)
        brows = (int(ey2), round(ey2 + hb))
        if not lit_like_bands(hsv, int(frag[0]), int(frag[1]), rrows, brows):  # where the white body shows
            continue
        reach = 1 + round(0.08 * w_exp)
        for q, (p0, p1) in enumerate(pieces):
            c0, c1 = round(p0), round(p1)
            on_l = (_continues(red, rrows, c0 - reach), _continues(blue, brows, c0 - reach))
            on_r = (_continues(red, rrows, c1 - 1 + reach), _continues(blue, brows, c1 - 1 + reach))
            inner_l, inner_r = q > 0 or ext_l, q < len(pieces) - 1 or ext_r  # cut by a split or an extension
            left, right = inner_l or any(on_l), inner_r or any(on_r)
            body_rows = (int(ey1) + 1, int(ey2))
            band_ends = (not (inner_l or all(on_l) or _white_on(hsv, body_rows, c0 - reach, white_v_min)),
                         not (inner_r or all(on_r) or _white_on(hsv, body_rows, c1 - 1 + reach, white_v_min)))
            rb = (c0 * scale, rrows[0] * scale, (c1 - c0) * scale, (rrows[1] - rrows[0]) * scale)
            bb = (c0 * scale, brows[0] * scale, (c1 - c0) * scale, (brows[1] - brows[0]) * scale)
            if any(_overlaps(rb, t) for t in taken):
                continue
            taken.append(rb)
            # the pattern fails in about one column at the limbs together (mixed pixels): count it back
            vis = min(seen, (p1 - p0 + 1) / w_exp) if len(pieces) == 1 else 1.0
            body = None if seen == 1.0 else (int(frag[0]) * scale, int(frag[1]) * scale)
            out.append(Candidate(rb, bb, gap * scale, red_merged, blue_merged, left, right, vis, hidden, body,
                                 band_ends=band_ends))
            if len(out) >= max_landmarks:
                return occluded_sides(out, scale)
    return occluded_sides(out, scale)


def _overlaps(a: BBox, b: BBox) -> bool:
    """Whether boxes a and b share more than half of the smaller one."""
    w = min(a[0] + a[2], b[0] + b[2]) - max(a[0], b[0])
    h = min(a[1] + a[3], b[1] + b[3]) - max(a[1], b[1])
    return w > 0 and h > 0 and w * h > 0.5 * min(a[2] * a[3], b[2] * b[3])
