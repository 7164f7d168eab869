"""The ``mimic`` preset: red-over-white-over-blue things that are NOT landmarks.

Each frame holds none to two robots with their landmarks and one to three of these, placed
where no landmark's image is (each differs from a landmark in one property at least):

``flag``    a striped poster on the wall (red, white, blue in equal stripes, or in the
            landmark's 15/40/15 proportions but many times wider than a landmark's 2:1
            silhouette): a flag, a sticker, a printed banner;
``cup``     a red cup on a white box on a blue floor mat (each a plain object of its own
            size: the cup wider or narrower than the box, the mat running on under it);
``can``     a red/white/blue striped can standing on the floor or on a grey box, its stripes
            in other proportions than a landmark's, or in a landmark's and of its height but
            two to four landmarks wide (a landmark scaled as a whole would image as a nearer
            landmark: no single picture tells them apart);
``stripes`` a red wall over a white skirting board over a blue mat (a room's own stripes).

One frame in four holds no landmark at all.
"""

from __future__ import annotations

import dataclasses
import math
from typing import List, Optional, Tuple

import numpy as np

from ..core.types import CameraIntrinsics
from . import looks
from . import sampling as d
from .camera import BoxPx, landmark_bbox_px
from .clutter import BLUE_PAINTS, RED_PAINTS, regions
from .robots import left_to_right, scatter, wall_behind
from .scene import RGB, WHITE_PAINT, Box, Cylinder, FloorPatch, LandmarkPose, Poster, Scene

MIMIC_PRESET = "mimic"
MIMIC_HELP = {MIMIC_PRESET: "red/white/blue things that are no landmark (flags, a red cup on a white box on a "
                            "blue mat, striped cans, a red wall over a skirting over a blue mat); 1 in 4 empty"}
KINDS = ("flag", "cup", "can", "stripes")
EMPTY_P = 0.25
GREY: RGB = (0.45, 0.45, 0.45)


def _paint(rng: np.random.Generator, table: Tuple[RGB, ...]) -> RGB:
    return d.jitter(rng, table[int(rng.integers(len(table)))], 0.03)


def _white(rng: np.random.Generator) -> RGB:
    return d.jitter(rng, WHITE_PAINT, 0.05)


def _proportions(rng: np.random.Generator) -> Tuple[float, float, float]:
    """Red, white, blue shares of a stripe stack unlike a landmark's 15/40/15."""
    if rng.random() < 0.5:
        return (1 / 3, 1 / 3, 1 / 3)  # a flag's equal stripes
    white = d.uniform(rng, 0.05, 0.2) if rng.random() < 0.5 else d.uniform(rng, 0.8, 0.9)
    return ((1 - white) / 2, white, (1 - white) / 2)


def _stack(bottom: float, height: float, shares: Tuple[float, float, float]) -> List[Tuple[float, float]]:
    """``(bottom, top)`` of the blue, white and red stripes of a stack, bottom first."""
    blue, white = bottom + shares[2] * height, bottom + (shares[2] + shares[1]) * height
    return [(bottom, blue), (blue, white), (white, bottom + height)]


def _flag(rng: np.random.Generator, scene: Scene, x: float) -> Scene:
    zw = scene.wall_distance_m
    if zw is None:
        return scene
    height = d.uniform(rng, 0.05, 0.3)
    if rng.random() < 0.5:
        shares, width = _proportions(rng), height * d.uniform(rng, 0.5, 2.0)
    else:  # the landmark's proportions, far wider than its silhouette
        shares, width = (15 / 70, 40 / 70, 15 / 70), height * d.uniform(rng, 3.0, 8.0)
    bottom = d.uniform(rng, 0.0, 0.35)
    x = x * zw
    paints = (_paint(rng, BLUE_PAINTS), _white(rng), _paint(rng, RED_PAINTS))
    posters = tuple(Poster(x - width / 2, x + width / 2, lo, hi, p)
                    for (lo, hi), p in zip(_stack(bottom, height, shares), paints))
    return dataclasses.replace(scene, posters=scene.posters + posters)


def _cup(rng: np.random.Generator, scene: Scene, x: float, z: float) -> Scene:
    box_w, box_h = d.uniform(rng, 0.05, 0.16), d.uniform(rng, 0.02, 0.12)
    cup_r, cup_h = d.uniform(rng, 0.02, 0.05), d.uniform(rng, 0.03, 0.1)
    box = Box(x * z, z, box_w, d.uniform(rng, 0.05, 0.12), 0.0, box_h, _white(rng))
    cup = Cylinder(x * z, z, cup_r, box_h, box_h + cup_h, _paint(rng, RED_PAINTS))
    w, far = d.uniform(rng, 0.2, 0.8), d.uniform(rng, 0.1, 0.6)
    mat = FloorPatch(x * z - w / 2, x * z + w / 2, z - d.uniform(rng, 0.1, 0.3), z + far, _paint(rng, BLUE_PAINTS))
    return dataclasses.replace(scene, boxes=(*scene.boxes, box), cylinders=(*scene.cylinders, cup),
                               floor_patches=(*scene.floor_patches, mat))


def _can(rng: np.random.Generator, scene: Scene, x: float, z: float) -> Scene:
    g = scene.geometry
    fat = rng.random() < 0.5
    radius = g.radius_m * (d.uniform(rng, 2.0, 4.0) if fat else d.uniform(rng, 0.8, 1.2))
    shares = (15 / 70, 40 / 70, 15 / 70) if fat else _proportions(rng)
    height = g.height_m * d.uniform(rng, 0.8, 1.25) if fat else g.height_m * d.uniform(rng, 0.7, 1.5)
    stand = d.uniform(rng, 0.02, 0.1) if rng.random() < 0.5 else 0.0
    paints = (_paint(rng, BLUE_PAINTS), _white(rng), _paint(rng, RED_PAINTS))
    cyls = tuple(Cylinder(x * z, z, radius, lo, hi, p) for (lo, hi), p in zip(_stack(stand, height, shares), paints))
    boxes = (Box(x * z, z, 2.2 * radius, 2.2 * radius, 0.0, stand, GREY),) if stand else ()
    return dataclasses.replace(scene, cylinders=scene.cylinders + cyls, boxes=scene.boxes + boxes)


def _stripes(rng: np.random.Generator, scene: Scene) -> Scene:
    zw = scene.wall_distance_m
    if zw is None:
        return scene
    half = zw * d.uniform(rng, 0.6, 1.5)
    skirting = d.uniform(rng, 0.02, 0.08)
    posters = (Poster(-half, half, 0.0, skirting, _white(rng)),)
    mat = FloorPatch(-half, half, zw - d.uniform(rng, 0.2, 0.8), zw, _paint(rng, BLUE_PAINTS))
    return dataclasses.replace(scene, wall_colour=_paint(rng, RED_PAINTS), posters=scene.posters + posters,
                               floor_patches=(*scene.floor_patches, mat))


def _clear(scene: Scene, boxes: List[BoxPx]) -> bool:
    """No mimic's image within 8 px of a landmark's (its robot's included)."""
    for lm in scene.landmarks:
        lb = landmark_bbox_px(scene, lm, with_robot=True)
        if lb is None:
            return False
        if any(min(lb[2], b[2]) - max(lb[0], b[0]) > -8.0 for b in boxes):
            return False
    return True


def _placed(rng: np.random.Generator, scene: Scene, kind: str) -> Optional[Scene]:
    """``scene`` with one mimic of ``kind`` at a random place in view, ``None`` when it would hide a landmark."""
    half = math.atan((scene.camera.width_px / 2 - 20) / scene.camera.fx_px)
    x = math.tan(d.uniform(rng, -half, half))  # X/Z of the mimic's axis
    zw = scene.wall_distance_m or 2.5
    z = d.uniform(rng, 0.25, max(0.3, min(1.6, zw - 0.15)))
    before = regions(scene)
    if kind == "flag":
        out = _flag(rng, scene, x)
    elif kind == "cup":
        out = _cup(rng, scene, x, z)
    elif kind == "can":
        out = _can(rng, scene, x, z)
    else:
        out = _stripes(rng, scene)
    new = [b for r, b in regions(out) if (r, b) not in before]
    if kind != "stripes" and not _clear(out, new):
        return None
    return out


def mimic_scene(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    """One ``mimic`` frame."""
    kind = looks.everyday(rng)
    base = looks.base_scene(rng, camera, kind)
    empty = rng.random() < EMPTY_P
    for _ in range(300):
        placed: List[LandmarkPose] = [] if empty else scatter(rng, base, int(rng.integers(1, 3)), 0.25, 1.2, [])
        if not empty and not placed:
            continue
        scene = wall_behind(dataclasses.replace(base, landmarks=left_to_right(placed)), rng, 0.1, 0.8, 0.0)
        if not scene.landmarks:
            scene = dataclasses.replace(scene, wall_distance_m=d.uniform(rng, 0.6, 1.8))
        picks = rng.choice(len(KINDS), int(rng.integers(1, 4)), replace=False).tolist()
        for i in sorted(picks):
            got = _placed(rng, scene, KINDS[i])
            scene = got if got is not None else scene
        if scene.posters or scene.cylinders or scene.boxes:
            return looks.finish(rng, scene, kind)
    raise d.give_up(MIMIC_PRESET, camera)


__all__ = ["KINDS", "MIMIC_HELP", "MIMIC_PRESET", "mimic_scene"]
