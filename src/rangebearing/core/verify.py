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

- **An object, not stripes** (:mod:`.stripes`): beside a landmark, at the rows of its red band
  and of its white body, lies something else, not both of its own colours again. A neighbouring
  candidate excuses its columns (a touching landmark shows its own bands there) unless it is
  rejected itself (:func:`verdicts`).
- **No twin** (:func:`twins`): a candidate of the same size beside it, its axis closer than
  two robots' landmarks can stand, makes both pieces of one wide thing (a flag's or a can's run
  cut into silhouettes).

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

from .crowding import ROBOT_APART_M, apart_m, crowded_out
from .detect import BandCentroids
from .edges import linear_table
from .model import normalised
from .params import ModelParams
from .stats import percentile
from .stripes import SAMPLES, striped
from .structure import one_run
from .types import BBox, CameraIntrinsics, LandmarkGeometry

# twins: landmarks' axes stand at least a robot's width apart (crowding.ROBOT_APART_M); right beside (px)
TWIN_PX = 1.5
TWIN_HEIGHT_M = 0.01  # ... and their centres at one height within this
TWINNED = "a candidate of its size beside it, closer than two robots' landmarks can stand: one thing cut"
JUNCTION_DIP = 0.8  # two limbs meeting: the body this much darker there than in either piece's middle (linear)
BAND_OVER_WHITE = 1.5  # a band's own channel may reach this share of the white body's (nominal 0.8)
WHITE_PCT, BAND_PCT = 90, 75  # robust levels: the body's brightest tenth, the bands' upper quartile
# height check: the tolerance is at least this, or 3 fitted sigmas ...
HEIGHT_MIN_TOL_M = 0.03
# ... plus the camera rocking (tan 0.5 deg) times the depth: a robot tilts on its wheels
PITCH_WOBBLE = 0.0087


def _level(bgr: np.ndarray, rows: Tuple[float, float], cols: Tuple[float, float], channel: int, pct: float) -> float:
    """Percentile ``pct`` of one linear-light channel (0 B, 2 R) over a region of the frame."""
    h, w = bgr.shape[:2]
    r0, r1 = max(0, round(rows[0])), min(h, round(rows[1]) + 1)
    c0, c1 = max(0, round(cols[0])), min(w, round(cols[1]) + 1)
    if r1 <= r0 or c1 <= c0:
        return float("nan")
    rs, cs = max(1, (r1 - r0) // SAMPLES), max(1, (c1 - c0) // SAMPLES)
    return percentile(bgr[r0:r1:rs, c0:c1:cs, channel], pct, linear_table())


def twins(bgr: np.ndarray, c: BandCentroids, o: BandCentroids, geometry: LandmarkGeometry,
          cam: CameraIntrinsics) -> bool:
    """Whether ``o`` stands beside ``c`` at so nearly its range and so close that no robot could carry it.

    Landmarks ride robots: their axes stand at least a robot's width apart (``ROBOT_APART_M``).
    Two candidates right beside each other (``2 TWIN_PX``) or overlapping in columns, their centres at
    one height (within ``TWIN_HEIGHT_M``), whose axes would stand closer than that (:func:`.crowding.apart_m`)
    are one thing cut in pieces: a flag, a poster or a can as wide as several landmarks, its run split into silhouettes;
    neither is a landmark. How far apart in depth they stand comes from their band spacings' measured
    difference plus ``crowding.SPACING_NOISE_PX`` (sub-pixel centroids of one size differ by that much): far away
    two robots one behind the other image at sizes only a few tenths of a pixel apart, and such a pair
    is no twin; a flag's pieces agree to a tenth, and a fat can's middle, nearer than its ends, images
    its bands a few pixels taller about the same centre.
    """
    if c is o:
        return False
    (x, _, w, _), (ox, _, ow, _) = c.bbox_px, o.bbox_px
    if not _beside(x, w, ox, ow):  # right beside it, or no twin
        return False
    if min(x + w, ox + ow) - max(x, ox) > 2 * TWIN_PX and not _one_run(c, o):  # overlapping: one run's pieces only
        return False
    spacing = c.blue_xy_px[1] - c.red_xy_px[1]
    if spacing <= 0:
        return False
    depth_m = geometry.band_spacing_m * cam.fy_px / spacing
    # at one height: the centres' rows (a wide can's middle is nearer than its ends: its bands image taller)
    rows_off = abs(c.red_xy_px[1] + c.blue_xy_px[1] - o.red_xy_px[1] - o.blue_xy_px[1]) / 2
    if rows_off * depth_m / cam.fy_px > TWIN_HEIGHT_M:
        return False
    return apart_m(c, o, geometry, cam) < ROBOT_APART_M and not limbs_between(bgr, c, o)


def _beside(x: float, w: float, ox: float, ow: float) -> bool:
    """Whether the columns ``[ox, ox + ow)`` lie right beside ``[x, x + w)`` (``2 TWIN_PX``) or overlap them."""
    return ox <= x + w + 2 * TWIN_PX and x <= ox + ow + 2 * TWIN_PX


def _one_run(c: BandCentroids, o: BandCentroids) -> bool:
    """Whether ``c`` and ``o`` were split from one run (:mod:`.structure`: the same band rows and white body).

    Two candidates overlapping in columns are two silhouettes of one wide run, or one landmark found
    twice (a fragment of it, its white body partly hidden, measured apart): only the first are twins."""
    a, b = c.candidate, o.candidate
    return a is not None and b is not None and one_run(a, b)


def _right_beside(c: BandCentroids, others: Sequence[BandCentroids], boxes: Sequence[BBox]) -> List[BandCentroids]:
    """The ``others`` (``boxes`` their ``bbox_px``) right beside ``c``: the only ones :func:`twins` can find twins."""
    x, _, w, _ = c.bbox_px
    return [o for o, (ox, _, ow, _) in zip(others, boxes) if o is not c and _beside(x, w, ox, ow)]


def limbs_between(bgr: np.ndarray, c: BandCentroids, o: BandCentroids) -> bool:
    """Whether the white body darkens where ``c`` and ``o`` meet: two cylinders' limbs, not one surface.

    A cylinder's surface turns away from the camera at its limbs: lit by anything but light the
    same from every side, one limb at least is darker than its middle, and where two landmarks
    touch two limbs meet. A flag is as light at the cut as either side; a can's surface turns
    smoothly through it, lit from one side lighter across the cut, the meeting between its two
    pieces' levels. Two landmarks side by side face the camera alike in their middles, each
    middle lighter than the limbs that meet. The darkest column within 2 px of the meeting
    (median over the middle of the body's rows) against the darker of the two pieces' middle
    fifths, in linear light.
    """
    a, b = sorted((c, o), key=lambda k: k.bbox_px[0])
    h, w = bgr.shape[:2]
    ry, by = c.red_xy_px[1], c.blue_xy_px[1]
    r0, r1 = max(0, round(ry + 0.35 * (by - ry))), min(h, round(by - 0.35 * (by - ry)) + 1)
    meet = round(0.5 * (a.bbox_px[0] + a.bbox_px[2] + b.bbox_px[0]))

    def columns(c0: float, c1: float) -> np.ndarray:
        c0, c1 = max(0, round(c0)), min(w, round(c1))
        if r1 <= r0 or c1 <= c0:
            return np.zeros(0)
        return (np.median(bgr[r0:r1, c0:c1].astype(np.float64).mean(axis=2), axis=0) / 255.0) ** 2.2

    joint = columns(meet - 2, meet + 3)
    middles = [columns(k.bbox_px[0] + 0.4 * k.bbox_px[2], k.bbox_px[0] + 0.6 * k.bbox_px[2] + 1) for k in (a, b)]
    if not len(joint) or not all(len(m) for m in middles):
        return True  # nothing to judge: not one thing
    return float(joint.min()) < JUNCTION_DIP * min(float(np.median(m)) for m in middles)


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
              cam: Optional[CameraIntrinsics] = None, others: Sequence[BandCentroids] = (),
              boxes: Optional[Sequence[BBox]] = None,
              twin_pool: Optional[Tuple[Sequence[BandCentroids], Sequence[BBox]]] = None) -> Optional[str]:
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
    boxes : sequence of BBox, optional
        ``o.bbox_px`` of each of ``others``, when the caller has them (:func:`verdicts`: once a frame).
    twin_pool : (candidates, their boxes), optional
        Whom ``c`` may be a twin of, when not ``others`` (:func:`verdicts`: the candidates not rejected
        for a reason of their own).
    """
    cand = c.candidate
    if model is not None and cam is not None and model.centre_sigma_m > 0:
        off, depth = height_off_m(c, model, cam)
        if abs(off) > height_tolerance_m(depth, model):
            return f"its centre is {100 * off:+.1f} cm off the height where landmarks stand"
    elif cand is not None and cand.red_merged and cand.blue_merged:
        return "both bands merge with their backgrounds: no edge of the landmark's own"
    boxes = [o.bbox_px for o in others] if boxes is None else boxes
    pool, pool_boxes = (others, boxes) if twin_pool is None else twin_pool
    if cam is not None and any(twins(bgr, c, o, geometry, cam) for o in _right_beside(c, pool, pool_boxes)):
        return TWINNED
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
    if striped(bgr, c, ((ry - 0.25 * band, ry + 0.25 * band), body), others, boxes):
        return "its red band and white body run on beside it: stripes, not an object"
    return None


def verdicts(bgr: np.ndarray, found: Sequence[BandCentroids], geometry: LandmarkGeometry,
             model: Optional[ModelParams] = None, cam: Optional[CameraIntrinsics] = None) -> List[Optional[str]]:
    """:func:`rejection` of each candidate, its neighbours the candidates not rejected.

    A neighbour excuses its columns from the stripes test because a landmark shows its own bands
    and body there; a "neighbour" rejected is no landmark, and stripes often hold several false
    candidates side by side (a skirting board cut by masts and robots), each excusing the next.
    The candidates passing are judged again against those still passing, once more at most. So is
    a candidate rejected only as the twin of another (:data:`TWINNED`) that shows a limb of its own,
    its twins now those not rejected for a reason of their own: a real landmark is not one thing with
    the stripes beside it (a band of the wall's hue), while the pieces of one can stay each other's
    twins, and a piece cut on both sides (no limb: a piece of something wider) stays one.
    """
    boxes = [c.bbox_px for c in found]  # a property: made once a frame, not once a pair
    why = [rejection(bgr, c, geometry, model, cam, found, boxes) for c in found]
    for _ in range(2):
        kept = [c for c, w in zip(found, why) if w is None]
        if len(kept) == len(found):
            break
        kept_boxes = [b for b, w in zip(boxes, why) if w is None]
        standing = [(c, b) for c, b, w in zip(found, boxes, why) if w in (None, TWINNED)]
        pool = ([c for c, _ in standing], [b for _, b in standing])
        again = [rejection(bgr, c, geometry, model, cam, kept, kept_boxes, pool) if w is None or (
                 w == TWINNED and _own_limb(c)) else w for c, w in zip(found, why)]
        if again == why:
            break
        why = again
    if model is not None and cam is not None and model.centre_sigma_m > 0 and why.count(None) > 1:
        offs = [height_off_m(c, model, cam)[0] if w is None else 0.0 for c, w in zip(found, why)]
        why = crowded_out(found, offs, why, geometry, cam)
    return why


def _own_limb(c: BandCentroids) -> bool:
    """Whether ``c`` shows a limb of its own (its run not cut on both sides): not only a piece of something wider."""
    cand = c.candidate
    return cand is None or not (cand.cut_left and cand.cut_right)


def verified(bgr: np.ndarray, found: Sequence[BandCentroids], geometry: LandmarkGeometry,
             model: Optional[ModelParams] = None, cam: Optional[CameraIntrinsics] = None) -> List[BandCentroids]:
    """The candidates that pass every check of :func:`rejection` (:func:`verdicts`), in their order."""
    return [c for c, w in zip(found, verdicts(bgr, found, geometry, model, cam)) if w is None]
