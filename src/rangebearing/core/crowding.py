"""Two candidates closer than two robots can stand: the one farther from the landmarks' height is no landmark.

Landmarks ride robots, so their axes stand at least a robot's width apart (``ROBOT_APART_M``,
as :func:`rangebearing.core.verify.twins` has it). A red wall over a pale floor over the navy top
plate of the robot carrying a real landmark reads red → white → blue right beside that landmark,
at its depth (the plate is that robot's own), a few centimetres from its axis: a second
"landmark" where no second robot fits. Its centre is not where landmarks stand, though: its blue
"band" is the plate under the real landmark's blue band, its red one the wall's foot, and the
pair's centres lie centimetres apart in height (twins, the pieces of one wide thing, lie at one
height and are :func:`~rangebearing.core.verify.twins`' to judge). Of two candidates whose axes
would stand closer than ``ROBOT_APART_M`` (their lateral distance and how far apart in depth their
band spacings put them), the one whose centre lies farther from the fitted height
(:func:`~rangebearing.core.verify.height_off_m`) is dropped; candidates are taken nearest that
height first, so each is judged against those kept.
"""

from __future__ import annotations

import math
from typing import List, Optional, Sequence

from .detect import BandCentroids
from .types import CameraIntrinsics, LandmarkGeometry

ROBOT_APART_M = 0.08  # landmarks' axes stand at least this far apart (a Zumo is 0.098 m by 0.086 m)
SPACING_NOISE_PX = 0.5  # band spacings measured alike differ by up to this (sub-pixel centroids)
CROWDED = "another candidate closer than two robots' landmarks can stand, and nearer the landmarks' height"


def apart_m(c: BandCentroids, o: BandCentroids, geometry: LandmarkGeometry, cam: CameraIntrinsics) -> float:
    """How close (m) the axes of ``c`` and ``o`` may stand: their lateral distance at ``c``'s depth and
    the depth between them their band spacings' difference (plus ``SPACING_NOISE_PX``) gives, combined."""
    spacing = c.blue_xy_px[1] - c.red_xy_px[1]
    if spacing <= 0:
        return math.inf
    depth_m = geometry.band_spacing_m * cam.fy_px / spacing
    lateral_m = abs(c.red_xy_px[0] + c.blue_xy_px[0] - o.red_xy_px[0] - o.blue_xy_px[0]) / 2 * depth_m / cam.fx_px
    dspacing = abs(spacing - (o.blue_xy_px[1] - o.red_xy_px[1])) + SPACING_NOISE_PX
    return math.hypot(lateral_m, depth_m * dspacing / spacing)


def crowded_out(found: Sequence[BandCentroids], offs_m: Sequence[float], why: Sequence[Optional[str]],
                geometry: LandmarkGeometry, cam: CameraIntrinsics) -> List[Optional[str]]:
    """``why`` with :data:`CROWDED` for each passing candidate closer than ``ROBOT_APART_M`` to one kept.

    Parameters
    ----------
    found : sequence of BandCentroids
        The frame's candidates.
    offs_m : sequence of float
        Each candidate's centre's distance (m) from the fitted landmark height (signed; its size ranks them).
    why : sequence of str or None
        Each candidate's rejection so far (``None``: it passes); rejected ones are not looked at.
    geometry, cam : LandmarkGeometry, CameraIntrinsics
        The landmark's dimensions and the frame's intrinsics.
    """
    out = list(why)
    kept: List[BandCentroids] = []
    for i in sorted((i for i, w in enumerate(why) if w is None), key=lambda i: abs(offs_m[i])):
        c = found[i]
        if any(apart_m(c, o, geometry, cam) < ROBOT_APART_M and apart_m(o, c, geometry, cam) < ROBOT_APART_M
               for o in kept):
            out[i] = CROWDED
        else:
            kept.append(c)
    return out
