"""The ``touching`` preset: landmarks against each other and against red and blue things.

Each frame holds 1–3 robots and one to three of these situations:

``pair``     a second robot right behind or beside the first, their landmarks'
             images touching or overlapping (offset 0.6–1.15 half-widths);
``red box``  a red (or blue) box right behind a landmark, its top edge crossing
             the landmark's image at a random height;
``wall``     a red or blue back wall close behind;
``mat``      a blue (or red) floor mat under and behind a robot;
``poster``   red and blue posters on the wall whose edges touch a landmark in
             the image;
``object``   a red or blue cylinder or box beside a landmark, touching it in
             the image.

One frame in eight holds the same kinds of things and no landmark at all (for
false-landmark checks).
"""

from __future__ import annotations

import dataclasses
import math
from typing import List, Tuple

import numpy as np

from ..core.types import CameraIntrinsics
from . import looks
from . import sampling as d
from .clutter import BLUE_PAINTS, RED_PAINTS
from .robots import landmark_half_angle, left_to_right, partner, scatter, wall_behind
from .scene import RGB, Box, Cylinder, FloorPatch, LandmarkPose, Poster, Scene

SITUATIONS = ("pair", "red box", "wall", "mat", "poster", "object")
EMPTY_P = 0.125


def _paint(rng: np.random.Generator, colour: str) -> RGB:
    table = RED_PAINTS if colour == "red" else BLUE_PAINTS
    return d.jitter(rng, table[int(rng.integers(len(table)))], 0.03)


def _foot(lm: LandmarkPose) -> float:
    return lm.body.footprint_m if lm.body else 0.05


def _box_behind(rng: np.random.Generator, scene: Scene, lm: LandmarkPose, colour: str) -> Box:
    h, g = scene.camera_height_m, scene.geometry
    depth = d.uniform(rng, 0.04, 0.2)
    z0 = lm.z_m + _foot(lm) + d.uniform(rng, 0.0, 0.1)
    hit = lm.base_height_m + d.uniform(rng, 0.3, 1.4) * g.height_m  # where its top edge crosses
    z_edge = z0 if hit > h else z0 + depth
    top = max(h + (hit - h) * z_edge / lm.z_m, 0.02)
    width = d.uniform(rng, 0.06, 0.3)
    x = lm.x_m * (z0 + depth / 2) / lm.z_m + d.uniform(rng, -0.4, 0.4) * width
    return Box(x, z0 + depth / 2, width, depth, 0.0, top, _paint(rng, colour))


def _beside(rng: np.random.Generator, scene: Scene, lm: LandmarkPose, colour: str):
    """A red or blue object whose image touches the landmark's from one side."""
    z = lm.z_m + d.uniform(rng, 0.0, 0.4) + _foot(lm)
    side = float(rng.choice([-1.0, 1.0]))
    a = landmark_half_angle(scene, lm.range_m)
    radius = d.uniform(rng, 0.015, 0.06)
    # its near edge at the landmark's image edge, give or take a little
    ang = lm.bearing_rad + side * (a + d.uniform(rng, -0.3, 0.3) * a) + side * radius / z
    x = -z * math.tan(ang)
    top = d.uniform(rng, 0.06, 0.2)
    if rng.random() < 0.5:
        return Cylinder(x, z, radius, 0.0, top, _paint(rng, colour))
    return Box(x, z, 2 * radius, 2 * radius, 0.0, top, _paint(rng, colour))


def _posters(rng: np.random.Generator, scene: Scene, lm: LandmarkPose) -> Tuple[Poster, ...]:
    zw = scene.wall_distance_m
    assert zw is not None
    h = scene.camera_height_m
    a = landmark_half_angle(scene, lm.range_m)
    out = []
    for side, colour in ((1.0, "red"), (-1.0, "blue")):
        if rng.random() < 0.3:
            continue
        edge = lm.bearing_rad + side * a * d.uniform(rng, 0.7, 1.2)
        xe = -zw * math.tan(edge)
        w = d.uniform(rng, 0.1, 0.5)
        x0, x1 = (xe - w, xe) if side > 0 else (xe, xe + w)
        lo = h + (lm.base_height_m - h) * zw / lm.z_m * d.uniform(rng, 0.0, 1.2)
        hi = h + (lm.base_height_m + scene.geometry.height_m - h) * zw / lm.z_m * d.uniform(rng, 0.8, 1.5)
        out.append(Poster(x0, x1, max(lo, 0.0), max(hi, lo + 0.05), _paint(rng, colour)))
    return tuple(out)


def touching_scene(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    """One ``touching`` frame."""
    kind = looks.everyday(rng)
    base = looks.base_scene(rng, camera, kind)
    empty = rng.random() < EMPTY_P
    for _ in range(300):
        placed: List[LandmarkPose] = scatter(rng, base, 1, 0.2, 1.2, [])
        if not placed:
            continue
        picks = set(rng.choice(len(SITUATIONS), int(rng.integers(1, 4)), replace=False).tolist())
        chosen = [SITUATIONS[i] for i in sorted(picks)]
        if "pair" in chosen:
            back = partner(rng, base, placed[0], placed, (0.6, 1.15), (0.16, 0.6))
            if back is None:
                continue
            placed.append(back)
        scatter(rng, base, int(rng.integers(0, 2)), 0.25, 1.4, placed)
        scene = wall_behind(dataclasses.replace(base, landmarks=left_to_right(placed)), rng,
                            0.05, 0.6, 0.0 if {"wall", "poster"} & set(chosen) else 0.2)
        boxes: List[Box] = []
        cyls: List[Cylinder] = []
        patches: List[FloorPatch] = []
        posters: Tuple[Poster, ...] = ()
        lm = placed[0]
        for what in chosen:
            colour = "red" if rng.random() < 0.6 else "blue"
            if what == "red box":
                boxes.append(_box_behind(rng, scene, lm, colour))
            elif what == "wall":
                scene = dataclasses.replace(scene, wall_colour=_paint(rng, colour))
            elif what == "mat":
                mat = "blue" if rng.random() < 0.7 else "red"
                w, far = d.uniform(rng, 0.3, 1.5), d.uniform(rng, 0.2, 2.0)
                x0 = lm.x_m - d.uniform(rng, 0.2, 0.8) * w
                patches.append(FloorPatch(x0, x0 + w, lm.z_m - d.uniform(rng, 0.1, 0.3),
                                          lm.z_m + far, _paint(rng, mat)))
            elif what == "poster":
                posters = _posters(rng, scene, lm)
            elif what == "object":
                obj = _beside(rng, scene, lm, colour)
                (cyls if isinstance(obj, Cylinder) else boxes).append(obj)  # type: ignore[arg-type]
        scene = dataclasses.replace(scene, boxes=tuple(boxes), cylinders=tuple(cyls),
                                    floor_patches=tuple(patches), posters=posters)
        if not _sound(scene):
            continue
        if empty:
            scene = dataclasses.replace(scene, landmarks=())
        return looks.finish(rng, scene, kind)
    raise d.give_up("touching", camera)


def _sound(scene: Scene) -> bool:
    """No object inside a robot's footprint or behind the wall."""
    zw = scene.wall_distance_m
    for o in (*scene.boxes, *scene.cylinders):
        r = o.radius_m if isinstance(o, Cylinder) else math.hypot(o.width_m, o.depth_m) / 2
        if zw is not None and o.z_m + r > zw:
            return False
        if o.z_m - r < 0.08:
            return False
        for lm in scene.landmarks:
            if math.hypot(o.x_m - lm.x_m, o.z_m - lm.z_m) < r + _foot(lm) + 0.003:
                return False
    return True
