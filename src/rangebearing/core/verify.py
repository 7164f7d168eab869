"""Is a measured candidate a landmark? Checks of properties every real landmark has, in any light.

The structure search (:mod:`.structure`) accepts columns that read red → white →
blue with the right proportions. Other things read so too: a red wall over a
grey wall over a navy mat, a robot's dark chassis between a red box and a blue
one, a neighbour's mast-mounted camera under a band. What they lack, and what
the checks here ask for:

- **Its place in the image.** Every robot carries its landmark at one height on
  one floor, so a landmark's centre lies a fixed height ``Y`` below the camera:
  at depth ``Z = S/L_n`` it images at the normalised row ``t + Y/Z`` (``t`` the
  horizon's row, the camera's pitch). ``calibrate`` fits ``Y``, ``t`` and their
  spread (``ModelParams.centre_below_m``, ``horizon_y_n``, ``centre_sigma_m``).
  A red–white–blue stack of other things has its own height: a wall's foot over
  the floor over a robot's blue top plate lies wholly below the horizon, its
  "landmark" a few centimetres lower than a landmark of its size can be. A
  candidate whose centre is more than :func:`height_tolerance_m` off is no
  landmark. The check reads only the two band rows and the calibration, so it
  holds in any light, against any background.
- **Its own band edges, when no height is fitted.** A band whose colour runs on
  past its outer edge (``red_merged``/``blue_merged``: a wall, box or mat of its
  colour behind it) is placed from its inner edge and the white height. When
  *both* bands merge, red over light over blue is all that is left, which any
  red surface over a light strip over a blue one shows too. Without a fitted
  height such a candidate is no landmark; with one, it must stand where a
  landmark of its size stands (a real landmark before a red wall and a blue mat
  does, the wall's foot over the floor does not).
- **A white body lighter than either band in the band's own channel.** White
  paint reflects more of every channel than the red or blue paint does (ours:
  red channel 0.85 against the red paint's 0.70, blue 0.85 against 0.65). The
  band and the body are one cylinder a few centimetres apart: the same light
  and, column by column, the same surface normal, so the ratio holds whatever
  the light's colour or strength. A dark chassis, a mast or a shadowed wall
  between two coloured things is far darker than the band in its channel.
  ``BAND_OVER_WHITE`` allows for light that changes along the height (the edge
  of a spotlight or of a shadow). Robust levels: the brightest tenth of the
  body (a neighbour's mast or camera in front of it darkens only part) and the
  upper quartile of each band's core.

- **An object, not stripes.** A white skirting board between an orange wall and
  a blue mat reads red → white → blue in every column along the wall; where
  something in front of the mat ends the blue for a while, the structure finds
  a "landmark" there. A landmark is an object: beside it, at the rows of its red
  band and of its white body, lies something else (a background, a wall), not
  both of its own colours again, lined up with its red band's and its body's
  own rows. A candidate whose band and body colours both run on, unchanged,
  right beside one of its sides is no landmark, whatever ends them on the
  other (a mast, a robot, a neighbour standing there; the stripes' end); nor is
  one whose colours run on beyond every side judged. Columns where another
  candidate stands are not looked at (touching neighbours show their own bands
  and bodies), but the rest of that side is: a real landmark right beside a
  skirting board excuses none of the board. Nor does a robot's mast and camera
  board in front of the stripes right beside the false one (what often ends
  it): the stripes run on when they show again a little farther out (on every
  side judged: farther out another object's own colours may show).

Levels are taken in linear light over the middle three fifths of the
candidate's visible columns (limbs darken and mix with the background); of
the columns where its white body shows, when its own camera hides the rest
(``Candidate.body_cols_px``). Each
check compares one channel with itself, so the white balance cancels.
"""

from __future__ import annotations

import math
from typing import List, Optional, Sequence, Tuple

import numpy as np

from .detect import BandCentroids
from .edges import linear_table
from .model import normalised
from .params import ModelParams
from .stats import percentile
from .types import CameraIntrinsics, LandmarkGeometry

BAND_OVER_WHITE = 1.5  # a band's own channel may reach this share of the white body's (nominal 0.8)
WHITE_PCT, BAND_PCT = 90, 75  # robust levels: the body's brightest tenth, the bands' upper quartile
SAMPLES = 24  # rows and columns sampled per region, at most
# height check: the tolerance is at least this, or 3 fitted sigmas ...
HEIGHT_MIN_TOL_M = 0.03
# ... plus the camera rocking (tan 0.5 deg) times the depth: a robot tilts on its wheels
PITCH_WOBBLE = 0.0087
# stripes: the colour beside the candidate, 0.15-0.6 of its width out, matches its own within this (log, per channel)
SIDE_REACH = (0.15, 0.6)
SIDE_WINDOWS, SIDE_STEP = 3, 0.45  # ... or in a window as wide this much farther out, up to 1.5 widths beyond a side
SAME_COLOUR_LOG = 0.25


def _level(bgr: np.ndarray, rows: Tuple[float, float], cols: Tuple[float, float], channel: int, pct: float) -> float:
    """Percentile ``pct`` of one linear-light channel (0 B, 2 R) over a region of the frame."""
    h, w = bgr.shape[:2]
    r0, r1 = max(0, round(rows[0])), min(h, round(rows[1]) + 1)
    c0, c1 = max(0, round(cols[0])), min(w, round(cols[1]) + 1)
    if r1 <= r0 or c1 <= c0:
        return float("nan")
    rs, cs = max(1, (r1 - r0) // SAMPLES), max(1, (c1 - c0) // SAMPLES)
    return percentile(bgr[r0:r1:rs, c0:c1:cs, channel], pct, linear_table())


def _colour(bgr: np.ndarray, rows: Tuple[float, float], cols: Tuple[float, float]) -> Optional[List[float]]:
    """Linear RGB (B, G, R order) of a region's median 8-bit colour, ``None`` when the region is empty."""
    h, w = bgr.shape[:2]
    r0, r1 = max(0, round(rows[0])), min(h, round(rows[1]) + 1)
    c0, c1 = max(0, round(cols[0])), min(w, round(cols[1]) + 1)
    if r1 <= r0 or c1 <= c0:
        return None
    rs, cs = max(1, (r1 - r0) // SAMPLES), max(1, (c1 - c0) // SAMPLES)
    # the median: a thin line of another colour in the region (a brick wall's mortar, a mast's edge) moves it not
    # (np.median's values; a sort of the few sampled pixels costs a third of its call)
    sub = np.sort(bgr[r0:r1:rs, c0:c1:cs].reshape(-1, 3), axis=0)
    n = sub.shape[0]
    return [((lo + hi) / 510.0) ** 2.2 for lo, hi in zip(sub[(n - 1) // 2].tolist(), sub[n // 2].tolist())]


def _same(a: Optional[List[float]], b: Optional[List[float]]) -> bool:
    return a is not None and b is not None and all(
        abs(math.log((x + 0.01) / (y + 0.01))) <= SAME_COLOUR_LOG for x, y in zip(a, b))


def _free(side: Tuple[float, float], boxes: Sequence[Tuple[float, float]]) -> Optional[Tuple[float, float]]:
    """The widest part of the column span ``side`` that no box's columns cover (``None``: under a third is free)."""
    cuts = sorted((max(lo, side[0]), min(hi, side[1])) for lo, hi in boxes if lo < side[1] and hi > side[0])
    best, at = (side[0], side[0]), side[0]
    for lo, hi in [*cuts, (side[1], side[1])]:
        if lo - at > best[1] - best[0]:
            best = (at, lo)
        at = max(at, hi)
    return best if best[1] - best[0] >= max(1.0, (side[1] - side[0]) / 3) else None


def _sides(c: BandCentroids, boxes: Sequence[Tuple[float, float]],
           frame_w: int) -> List[Tuple[bool, List[Tuple[float, float]]]]:
    """Per side of ``c`` judged (its nearest window free), whether its run was cut there and the free column spans
    of its windows, nearest first (farther windows only on a cut side: one that ends at its limb shows what lies
    beside it)."""
    x, _, w, _ = c.bbox_px
    cand = c.candidate
    out = []
    for sign, cut in ((-1.0, cand is not None and cand.cut_left), (1.0, cand is not None and cand.cut_right)):
        found: List[Tuple[float, float]] = []
        for k in range(SIDE_WINDOWS if cut else 1):
            near, far = SIDE_REACH[0] + k * SIDE_STEP, SIDE_REACH[1] + k * SIDE_STEP
            span = (x - far * w, x - near * w) if sign < 0 else (x + w + near * w, x + w + far * w)
            if k and (span[0] < 0 or span[1] > frame_w - 1):  # a farther window past the frame's edge: none
                break
            free = _free(span, boxes)
            if free:
                found.append(free)
            elif not k:  # a neighbour right beside it: the side is not judged (it shows the neighbour)
                break
        if found:
            out.append((cut, found))
    return out


def striped(bgr: np.ndarray, c: BandCentroids, layers: Sequence[Tuple[float, float]],
            others: Sequence[BandCentroids] = ()) -> bool:
    """Whether the colours of ``layers`` (row spans) run on unchanged beyond the sides of ``c``.

    Columns where another candidate stands are not looked at (a touching
    neighbour shows its own bands and body there): a side is judged on what is
    left of its window 0.15-0.6 of the width out, and a side whose window a
    neighbour covers (two thirds or more) not at all. The layers run on beyond a
    judged side when they show unchanged in that window or, where the run was
    cut on that side (it ends at something other than a limb), in one of the
    ``SIDE_WINDOWS - 1`` as wide stepping outwards (0.45 of the width each, on
    what no neighbour covers): a thin thing in front of the stripes right beside
    it (a robot's mast and camera board, which often end the false "landmark")
    does not hide that they go on. Stripes: the layers show unchanged right
    beside one side judged (no background beside a real landmark lines up red
    and white with its band's and its body's rows), or beyond every side judged,
    and at least one is. Colours are medians (a brick wall's mortar or a mast's
    edge in a window moves them not).
    """
    boxes = [(b[0] - 1.0, b[0] + b[2] + 1.0) for b in (o.bbox_px for o in others if o is not c)]  # a property: once
    sides = _sides(c, boxes, bgr.shape[1])
    if not sides:
        return False
    x, _, w, _ = c.bbox_px
    own: dict = {}  # each layer's own colour, measured when first needed

    def same(rows: Tuple[float, float], span: Tuple[float, float]) -> bool:
        if rows not in own:
            own[rows] = _colour(bgr, rows, (x + 0.2 * w, x + 0.8 * w))
        return _same(own[rows], _colour(bgr, rows, span))

    # body first: beside most real landmarks it is the background, and one differing layer ends the test
    def runs_on(span: Tuple[float, float]) -> bool:
        return all(same(rows, span) for rows in reversed(layers))

    if any(not cut and runs_on(windows[0]) for cut, windows in sides):  # beside a limb that is none
        return True
    return all(any(map(runs_on, windows)) for _, windows in sides)


def height_tolerance_m(depth_m: float, model: ModelParams) -> float:
    """How far (m) a landmark's centre at ``depth_m`` may lie from the fitted height."""
    return max(HEIGHT_MIN_TOL_M, 3.0 * model.centre_sigma_m) + PITCH_WOBBLE * depth_m


def height_off_m(c: BandCentroids, model: ModelParams, cam: CameraIntrinsics) -> Tuple[float, float]:
    """``(off_m, depth_m)``: how far the candidate's centre lies below the fitted landmark height, and its depth."""
    if cam.has_distortion:
        (xr, yr), (xb, yb) = normalised(np.array([c.red_xy_px, c.blue_xy_px]), cam)
    else:  # as model.pinhole_reading: the common case without numpy
        xr, yr = (c.red_xy_px[0] - cam.cx_px) / cam.fx_px, (c.red_xy_px[1] - cam.cy_px) / cam.fy_px
        xb, yb = (c.blue_xy_px[0] - cam.cx_px) / cam.fx_px, (c.blue_xy_px[1] - cam.cy_px) / cam.fy_px
    l_n = math.hypot(xb - xr, yb - yr)
    depth = model.spacing_m / max(l_n, 1e-9)
    return (0.5 * (yr + yb) - model.horizon_y_n) * depth - model.centre_below_m, depth


def rejection(bgr: np.ndarray, c: BandCentroids, geometry: LandmarkGeometry, model: Optional[ModelParams] = None,
              cam: Optional[CameraIntrinsics] = None, others: Sequence[BandCentroids] = ()) -> Optional[str]:
    """Why ``c`` is no landmark, or ``None`` when it passes every check (see the module docstring).

    Parameters
    ----------
    bgr : (H, W, 3) uint8
        The full-resolution frame the candidate was measured in.
    c : BandCentroids
        The measured candidate (its band rows and visible columns).
    geometry : LandmarkGeometry
        The landmark's dimensions (band and white heights from the band spacing).
    model, cam : ModelParams, CameraIntrinsics, optional
        The calibration and the frame's intrinsics: with a fitted height
        (``model.centre_sigma_m > 0``) the candidate must stand at it.
    others : sequence of BandCentroids
        The frame's other candidates (touching neighbours are no stripes).
    """
    cand = c.candidate
    if model is not None and cam is not None and model.centre_sigma_m > 0:
        off, depth = height_off_m(c, model, cam)
        if abs(off) > height_tolerance_m(depth, model):
            return f"its centre is {100 * off:+.1f} cm off the height where landmarks stand"
    elif cand is not None and cand.red_merged and cand.blue_merged:
        return "both bands merge with their backgrounds: no edge of the landmark's own"
    ry, by = c.red_xy_px[1], c.blue_xy_px[1]
    spacing = by - ry
    if spacing <= 0:
        return "the blue band is not below the red one"
    band = spacing * geometry.band_height_m / geometry.band_spacing_m
    white = spacing * (geometry.height_m - 2 * geometry.band_height_m) / geometry.band_spacing_m
    x, _, w, _ = c.bbox_px
    if cand is not None and cand.body_cols_px is not None:  # its own camera hides the rest of the body
        x, w = cand.body_cols_px[0], cand.body_cols_px[1] - cand.body_cols_px[0]  # bands and body where it shows
    cols = (x + 0.2 * w, x + 0.8 * w)
    red_r = _level(bgr, (ry - 0.25 * band, ry + 0.25 * band), cols, 2, BAND_PCT)
    blue_b = _level(bgr, (by - 0.25 * band, by + 0.25 * band), cols, 0, BAND_PCT)
    body = (ry + 0.5 * band + 0.15 * white, by - 0.5 * band - 0.15 * white)
    white_r = _level(bgr, body, cols, 2, WHITE_PCT)
    white_b = _level(bgr, body, cols, 0, WHITE_PCT)
    if red_r > BAND_OVER_WHITE * white_r or blue_b > BAND_OVER_WHITE * white_b:
        return "the white body is darker than a band in the band's own channel"
    if striped(bgr, c, ((ry - 0.25 * band, ry + 0.25 * band), body), others):
        return "its red band and white body run on beside it: stripes, not an object"
    return None


def verified(bgr: np.ndarray, found: Sequence[BandCentroids], geometry: LandmarkGeometry,
             model: Optional[ModelParams] = None, cam: Optional[CameraIntrinsics] = None) -> List[BandCentroids]:
    """The candidates that pass every check of :func:`rejection`, in their order."""
    return [c for c in found if rejection(bgr, c, geometry, model, cam, found) is None]
