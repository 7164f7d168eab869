"""Random Zumo-like robots and collision-free placements in the camera's view.

Used by the ``occlusion``, ``touching``, ``crowd``, ``far``, ``lighting`` and
``crowd-moving`` presets. Robots stand where real ones could (footprints apart,
the camera robot's own footprint clear); whether one hides another is left to
the geometry, and the truth measures it (see :mod:`.visibility`).
"""

from __future__ import annotations

import dataclasses
import math
from typing import List, Optional, Sequence

import numpy as np

from ..core.types import CameraIntrinsics
from . import sampling as d
from .scene import RGB, LandmarkPose, RobotBody, Scene

MAST_COLOURS = {
    "black": (0.035, 0.035, 0.035),
    "dark grey": (0.08, 0.08, 0.08),
    "bluish": (0.045, 0.05, 0.10),  # the dark, slightly bluish pedestal of the issue
    "reddish": (0.09, 0.045, 0.045),
    "grey": (0.22, 0.22, 0.23),
}
BOARD_COLOURS = ((0.05, 0.16, 0.07), (0.03, 0.05, 0.12), (0.04, 0.04, 0.04), (0.12, 0.02, 0.02))
CAMERA_COLOURS = ((0.05, 0.16, 0.07), (0.04, 0.04, 0.04))  # Pi camera boards: green or black
CLEARANCE_M = 0.01
OWN_FOOTPRINT_M = 0.07  # the camera robot itself


def zumo(rng: np.random.Generator) -> RobotBody:
    """A robot body with its own paint: mast colour and radius, board colour, shade of black."""
    mast = d.jitter(rng, d.pick(rng, MAST_COLOURS), 0.01)
    board: RGB = BOARD_COLOURS[int(rng.integers(len(BOARD_COLOURS)))]
    black = d.uniform(rng, 0.02, 0.06)
    camera = CAMERA_COLOURS[int(rng.integers(len(CAMERA_COLOURS)))]
    return RobotBody(mast_radius_m=d.uniform(rng, 0.008, 0.017), mast_colour=mast,
                     board_colour=d.jitter(rng, board, 0.01), camera_colour=d.jitter(rng, camera, 0.01),
                     chassis_colour=(black, black, black * 1.05),
                     track_colour=(black * 0.7, black * 0.7, black * 0.7))


def half_fov_rad(camera: CameraIntrinsics) -> float:
    """Half the horizontal field of view (the narrower side)."""
    left = math.atan((camera.cx_px + 0.5) / camera.fx_px)
    right = math.atan((camera.width_px - 0.5 - camera.cx_px) / camera.fx_px)
    return min(left, right)


def apart(lm: LandmarkPose, placed: Sequence[LandmarkPose], extra_m: float = 0.0) -> bool:
    """Whether a robot at ``lm`` stays clear of every placed robot and of the camera robot."""
    r = lm.body.footprint_m if lm.body else 0.05
    if lm.range_m < r + OWN_FOOTPRINT_M:
        return False
    for o in placed:
        ro = o.body.footprint_m if o.body else 0.05
        if math.hypot(lm.x_m - o.x_m, lm.z_m - o.z_m) < r + ro + CLEARANCE_M + extra_m:
            return False
    return True


def robot(rng: np.random.Generator, range_m: float, bearing_rad: float,
          base_spread_m: float = 0.012, robot_id: int = -1) -> LandmarkPose:
    """A Zumo-like robot with a random heading and mast height at ``range_m, bearing_rad``."""
    base = d.DEFAULT_BASE_HEIGHT_M + d.uniform(rng, -1.0, 1.0) * base_spread_m
    return LandmarkPose(range_m, bearing_rad, base, d.uniform(rng, -math.pi, math.pi), zumo(rng),
                        robot_id)


def landmark_half_angle(scene: Scene, range_m: float) -> float:
    """Angular half-width of a landmark at ``range_m``."""
    return math.asin(min(1.0, scene.geometry.radius_m / range_m))


def partner(rng: np.random.Generator, scene: Scene, front: LandmarkPose, placed: Sequence[LandmarkPose],
            overlap: tuple, depth_m: tuple = (0.16, 0.9), attempts: int = 60) -> Optional[LandmarkPose]:
    """A robot behind ``front`` whose landmark's image is offset from the front one's by
    ``k`` times the sum of their half-widths, ``k`` drawn from ``overlap`` (0 = right
    behind it, 1 = just touching, > 1 = a gap)."""
    a = landmark_half_angle(scene, front.range_m)
    for _ in range(attempts):
        r = front.range_m + d.uniform(rng, *depth_m)
        k = d.uniform(rng, *overlap) * float(rng.choice([-1.0, 1.0]))
        b = front.bearing_rad + k * (a + landmark_half_angle(scene, r))
        cand = robot(rng, r, b)
        if abs(b) < half_fov_rad(scene.camera) and apart(cand, placed):
            return cand
    return None


def scatter(rng: np.random.Generator, scene: Scene, n: int, r_lo: float, r_hi: float,
            placed: List[LandmarkPose], edge_out: float = 0.0, attempts: int = 400) -> List[LandmarkPose]:
    """Up to ``n`` more robots anywhere in view (log-uniform range); ``edge_out`` lets a
    landmark's axis go that many half-widths past the frame edge."""
    half = half_fov_rad(scene.camera)
    for _ in range(attempts):
        if n <= 0:
            break
        r = d.log_uniform(rng, r_lo, r_hi)
        lim = half + edge_out * landmark_half_angle(scene, r)
        lo, hi = d.bearing_limits(scene.camera, r, scene.geometry.radius_m)
        if edge_out <= 0.0:
            lim_lo, lim_hi = lo, hi
        else:
            lim_lo, lim_hi = -lim, lim
        if lim_lo >= lim_hi:
            continue
        cand = robot(rng, r, d.uniform(rng, lim_lo, lim_hi))
        if edge_out <= 0.0 and not d.in_view(scene, cand):
            continue
        if apart(cand, placed):
            placed.append(cand)
            n -= 1
    return placed


def wall_behind(scene: Scene, rng: np.random.Generator, lo: float, hi: float,
                open_room_p: float = 0.0) -> Scene:
    """The back wall ``lo``–``hi`` m behind the farthest robot (or an open room)."""
    if rng.random() < open_room_p:
        return dataclasses.replace(scene, wall_distance_m=None)
    far = max([lm.z_m + (lm.body.footprint_m if lm.body else 0.05) for lm in scene.landmarks]
              + [0.3])
    return dataclasses.replace(scene, wall_distance_m=far + d.uniform(rng, lo, hi))


def left_to_right(lms: Sequence[LandmarkPose]) -> tuple:
    """Landmarks in image order, left first."""
    return tuple(sorted(lms, key=lambda lm: -lm.bearing_rad))
