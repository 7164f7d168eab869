"""Presets with Zumo-like robots: ``occlusion``, ``crowd``, ``far``, ``lighting`` and ``rooms``.

``occlusion``  2–4 robots, 0.2–1.6 m; one is drawn right behind another (its
               landmark's image offset by 0–1.2 half-widths, so from wholly
               hidden to just touching), and a third of the frames put a plain
               box in front of a landmark, hiding it up to a random height.
``crowd``      5–8 robots, 0.2–1.8 m, landmarks allowed past the frame edges.
``far``        one robot, 0.15–2.0 m (log-uniform), anywhere it is wholly in
               view, hard rooms and light.
``lighting``   1–3 robots apart in the image, 0.2–1.5 m, each frame under one of
               :data:`.looks.LIGHT_KINDS` (dim, bright, warm, cool, coloured,
               spotlit, backlit, normal).
``rooms``      ``lighting`` frames in a room of one strong colour: a red carpet
               and red brick walls, or a navy carpet and blue walls (the whole
               frame cast red or blue: grey-world and any camera balance pulled).

Which landmark hides which is left to the geometry; the truth measures it.
"""

from __future__ import annotations

import dataclasses
import math
from typing import List, Optional

import numpy as np

from ..core.types import CameraIntrinsics
from . import looks
from . import sampling as d
from .robots import apart, landmark_half_angle, left_to_right, partner, robot, scatter, wall_behind
from .scene import Box, LandmarkPose, Scene

BOX_COLOURS = ((0.55, 0.42, 0.28), (0.62, 0.60, 0.56), (0.30, 0.30, 0.32), (0.70, 0.66, 0.55))


def occluder(rng: np.random.Generator, scene: Scene, lm: LandmarkPose,
             placed: List[LandmarkPose]) -> Optional[Box]:
    """A plain box between the camera and ``lm`` whose top edge, seen from the camera,
    crosses the landmark at a random height (hiding what is below it)."""
    h, g = scene.camera_height_m, scene.geometry
    foot = lm.body.footprint_m if lm.body else 0.05
    for _ in range(30):
        depth = d.uniform(rng, 0.02, 0.06)
        z_far = lm.z_m - foot - d.uniform(rng, 0.01, 0.12)  # the box's face towards the robot
        z_near = z_far - depth
        if z_near < 0.1:
            return None
        hide = lm.base_height_m + d.uniform(rng, -0.01, 0.75) * g.height_m
        z_edge = z_far if hide < h else z_near  # the top edge that makes the silhouette
        top = h - (h - hide) * z_edge / lm.z_m
        width = d.uniform(rng, 0.04, 0.25)
        x = lm.x_m * (z_far - depth / 2) / lm.z_m + d.uniform(rng, -0.6, 0.6) * width / 2
        box = Box(x, z_far - depth / 2, width, depth, 0.0, top,
                  d.jitter(rng, BOX_COLOURS[int(rng.integers(len(BOX_COLOURS)))], 0.03))
        if top > 0.01 and all(_clear(box, o) for o in placed):
            return box
    return None


def _clear(box: Box, lm: LandmarkPose) -> bool:
    foot = lm.body.footprint_m if lm.body else 0.05
    dx = max(abs(lm.x_m - box.x_m) - box.width_m / 2, 0.0)
    dz = max(abs(lm.z_m - box.z_m) - box.depth_m / 2, 0.0)
    return math.hypot(dx, dz) > foot + 0.005


def occlusion_scene(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    """One ``occlusion`` frame."""
    n = int(rng.integers(2, 5))
    kind = looks.everyday(rng)
    base = looks.base_scene(rng, camera, kind)
    for _ in range(300):
        placed: List[LandmarkPose] = scatter(rng, base, 1, 0.2, 1.0, [])
        if not placed:
            continue
        back = partner(rng, base, placed[0], placed, (0.0, 1.2))
        if back is None:
            continue
        placed.append(back)
        scatter(rng, base, n - 2, 0.2, 1.6, placed)
        if len(placed) < n:
            continue
        boxes = ()
        if rng.random() < 0.33:
            box = occluder(rng, base, placed[int(rng.integers(len(placed)))], placed)
            boxes = (box,) if box is not None else ()
        scene = dataclasses.replace(base, landmarks=left_to_right(placed), boxes=boxes)
        return looks.finish(rng, wall_behind(scene, rng, 0.25, 1.2, 0.2), kind)
    raise d.give_up("occlusion", camera)


def crowd_scene(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    """One ``crowd`` frame: 5–8 robots, some past the frame edges."""
    n = int(rng.integers(5, 9))
    kind = looks.everyday(rng)
    base = looks.base_scene(rng, camera, kind)
    for _ in range(100):
        placed = scatter(rng, base, n, 0.2, 1.8, [], edge_out=2.0, attempts=1500)
        if len(placed) == n:
            scene = dataclasses.replace(base, landmarks=left_to_right(placed))
            return looks.finish(rng, wall_behind(scene, rng, 0.25, 1.2, 0.2), kind)
    raise d.give_up("crowd", camera)


def far_scene(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    """One ``far`` frame: one robot wholly in view, 0.15–2.0 m."""
    kind = looks.any_light(rng)
    base = looks.base_scene(rng, camera, kind, camera_height=(0.09, 0.11))
    for _ in range(2000):
        r = d.log_uniform(rng, 0.15, 2.0)
        lo, hi = d.bearing_limits(camera, r, base.geometry.radius_m)
        if lo >= hi:
            continue
        lm = robot(rng, r, d.uniform(rng, lo, hi), base_spread_m=0.02)
        if d.in_view(base, lm) and apart(lm, []):
            scene = dataclasses.replace(base, landmarks=(lm,))
            return looks.finish(rng, wall_behind(scene, rng, 0.3, 1.5, 0.25), kind)
    raise d.give_up("far", camera)


def _apart_in_image(scene: Scene, lm: LandmarkPose, placed: List[LandmarkPose]) -> bool:
    a = landmark_half_angle(scene, lm.range_m)
    return all(abs(lm.bearing_rad - o.bearing_rad) > 1.5 * (a + landmark_half_angle(scene, o.range_m))
               for o in placed)


def lighting_scene(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    """One ``lighting`` frame: 1–3 robots apart in the image under one of the light kinds."""
    kind = looks.LIGHT_KINDS[int(rng.integers(len(looks.LIGHT_KINDS)))]
    n = int(rng.integers(1, 4))
    base = looks.base_scene(rng, camera, kind, camera_height=(0.095, 0.105))
    for _ in range(300):
        placed: List[LandmarkPose] = []
        for _ in range(60):
            if len(placed) == n:
                break
            r = d.log_uniform(rng, 0.2, 1.5)
            lo, hi = d.bearing_limits(camera, r, base.geometry.radius_m)
            if lo >= hi:
                continue
            lm = robot(rng, r, d.uniform(rng, lo, hi))
            if d.in_view(base, lm) and apart(lm, placed) and _apart_in_image(base, lm, placed):
                placed.append(lm)
        if len(placed) == n:
            scene = dataclasses.replace(base, landmarks=left_to_right(placed))
            return looks.finish(rng, wall_behind(scene, rng, 0.3, 1.2, 0.15), kind)
    raise d.give_up("lighting", camera)


# (floor, wall) of a room of one colour: the carpets and walls of :mod:`.looks`, both of one hue
ROOM_CASTS = {"red": ("red carpet", "red brick"), "blue": ("navy carpet", "blue paint")}


def rooms_scene(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    """One ``rooms`` frame: a ``lighting`` frame whose floor and walls are all red or all blue."""
    floor, wall = ROOM_CASTS[("red", "blue")[int(rng.integers(2))]]
    scene = lighting_scene(rng, camera)
    return dataclasses.replace(scene, floor_colour=d.jitter(rng, looks.FLOORS[floor], 0.015),
                               wall_colour=d.jitter(rng, looks.WALLS[wall], 0.02))
