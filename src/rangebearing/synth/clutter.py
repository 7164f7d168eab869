"""The ``clutter`` preset: red and blue things that are NOT landmarks.

Half the frames hold one landmark, half none. Distractors: red-only and
blue-only cylinders and boxes, a red box high on a pedestal above a blue
cylinder, red and blue cylinders side by side, a red poster on the wall,
large tinted floor regions. :func:`landmark_like` is the rule every layout
must pass: no red region overlaps a blue one horizontally while their centres
are closer than five widths vertically (a landmark's bands: 1.6 widths).
"""

from __future__ import annotations

import colorsys
import dataclasses
import math
from typing import List, Optional, Tuple, Union

import numpy as np

from ..core.types import CameraIntrinsics
from . import sampling as d
from .camera import BoxPx, cylinder_bbox_px, landmark_bbox_px, points_bbox
from .scene import RGB, Box, Cylinder, FloorPatch, LandmarkPose, Poster, Scene

RED_PAINTS = ((0.70, 0.07, 0.06), (0.78, 0.10, 0.08), (0.62, 0.05, 0.10), (0.75, 0.16, 0.05))
BLUE_PAINTS = ((0.06, 0.12, 0.65), (0.05, 0.18, 0.70), (0.10, 0.10, 0.58), (0.04, 0.22, 0.60))
PATCH_TINTS = ((0.55, 0.30, 0.24), (0.25, 0.32, 0.50), (0.38, 0.50, 0.32), (0.55, 0.38, 0.24))
PEDESTAL: RGB = (0.45, 0.45, 0.45)
GAP_PX = 6.0


def colour_class(rgb: RGB) -> Optional[str]:
    """``"red"``, ``"blue"`` or None for a reflectance, judged after gamma as a camera would."""
    r, g, b = (c ** (1 / 2.2) for c in rgb)
    hue, sat, _ = colorsys.rgb_to_hsv(r, g, b)
    if sat < 0.2:
        return None
    if hue < 25 / 360 or hue > 330 / 360:
        return "red"
    if 190 / 360 < hue < 265 / 360:
        return "blue"
    return None


def _grid(a: Tuple[float, float], b: Tuple[float, float], c: Tuple[float, float]) -> Tuple[np.ndarray, ...]:
    s = [np.linspace(lo, hi, 9) for lo, hi in (a, b, c)]
    return tuple(m.ravel() for m in np.meshgrid(*s))


def regions(scene: Scene) -> List[Tuple[str, BoxPx]]:
    """Image extents of the scene's red and blue things other than landmarks."""
    out: List[Tuple[str, BoxPx]] = []

    def add(colour: RGB, box: Optional[BoxPx]) -> None:
        cls = colour_class(colour)
        if cls is not None and box is not None:
            out.append((cls, box))

    for c in scene.cylinders:
        add(c.colour, cylinder_bbox_px(scene, c.x_m, c.z_m, c.radius_m, c.bottom_m, c.top_m))
    for b in scene.boxes:
        add(
            b.colour,
            points_bbox(
                scene,
                *_grid(
                    (b.x_m - b.width_m / 2, b.x_m + b.width_m / 2),
                    (b.bottom_m, b.top_m),
                    (b.z_m - b.depth_m / 2, b.z_m + b.depth_m / 2),
                ),
            ),
        )
    if scene.wall_distance_m is not None:
        zw = scene.wall_distance_m
        for p in scene.posters:
            add(p.colour, points_bbox(scene, *_grid((p.x_min_m, p.x_max_m), (p.bottom_m, p.top_m), (zw, zw))))
    for f in scene.floor_patches:
        z0 = max(f.z_min_m, 0.05)
        if f.z_max_m > z0:
            add(f.colour, points_bbox(scene, *_grid((f.x_min_m, f.x_max_m), (0.0, 0.0), (z0, f.z_max_m))))
    return out


def landmark_like(red: BoxPx, blue: BoxPx) -> bool:
    """Whether a red and a blue region could pair up as a landmark's bands.

    Conservative: any red and blue regions that overlap horizontally (or come
    within ``GAP_PX``) with centres less than five widths apart vertically, in
    either order (occlusion can cut a red top off a blue-fronted object).
    """
    if min(red[2], blue[2]) - max(red[0], blue[0]) < -GAP_PX:
        return False  # side by side
    red_v, blue_v = (red[1] + red[3]) / 2, (blue[1] + blue[3]) / 2
    width = max(red[2] - red[0], blue[2] - blue[0], 1.0)
    return abs(blue_v - red_v) < 5.0 * width


Solid = Union[Cylinder, Box]


def _footprint(obj: Solid) -> Tuple[float, float, float, float, float]:
    """``(x, z, radius, bottom, top)`` of a bounding vertical cylinder."""
    if isinstance(obj, Cylinder):
        return obj.x_m, obj.z_m, obj.radius_m, obj.bottom_m, obj.top_m
    return obj.x_m, obj.z_m, math.hypot(obj.width_m, obj.depth_m) / 2, obj.bottom_m, obj.top_m


def _collide(a: Tuple[float, ...], b: Tuple[float, ...]) -> bool:
    apart = math.hypot(a[0] - b[0], a[1] - b[1]) >= a[2] + b[2] + 0.01
    stacked = a[3] >= b[4] - 1e-9 or b[3] >= a[4] - 1e-9
    return not (apart or stacked)


def layout_ok(scene: Scene) -> bool:
    """No landmark-like pair, nothing near a landmark, no two objects interpenetrating."""
    found = regions(scene)
    reds = [b for c, b in found if c == "red"]
    blues = [b for c, b in found if c == "blue"]
    if any(landmark_like(r, b) for r in reds for b in blues):
        return False
    objects: List[Solid] = [*scene.cylinders, *scene.boxes]
    feet = [_footprint(o) for o in objects]
    g = scene.geometry
    feet += [(lm.x_m, lm.z_m, scene.robot_radius_m, 0.0, lm.base_height_m + g.height_m) for lm in scene.landmarks]
    if any(_collide(a, b) for i, a in enumerate(feet) for b in feet[:i]):
        return False
    if scene.wall_distance_m is not None and any(f[1] + f[2] > scene.wall_distance_m for f in feet):
        return False
    others = [b for _, b in found] + [cylinder_bbox_px(scene, *_footprint(o)[:3], 0.0, 1.0) for o in objects]
    for lm in scene.landmarks:
        box = landmark_bbox_px(scene, lm, with_robot=True)
        if box is None:
            return False
        for other in others:
            if other is not None and min(box[2], other[2]) - max(box[0], other[0]) > -GAP_PX:
                return False
    return True


def _distractors(rng: np.random.Generator, scene: Scene) -> Scene:
    cam: CameraIntrinsics = scene.camera
    half = math.atan(cam.width_px / 2 / cam.fx_px)
    zmax = (scene.wall_distance_m or 3.0) - 0.15
    cyl: List[Cylinder] = list(scene.cylinders)
    box: List[Box] = list(scene.boxes)
    posters: List[Poster] = []
    patches: List[FloorPatch] = []

    def spot(zlo: float = 0.3) -> Tuple[float, float]:
        z = d.uniform(rng, zlo, max(zlo + 0.05, min(2.0, zmax)))
        return -z * math.tan(d.uniform(rng, -half, half)), z

    def paint(kind: str) -> RGB:
        table = RED_PAINTS if kind == "red" else BLUE_PAINTS
        return d.jitter(rng, table[int(rng.integers(len(table)))], 0.02)

    for _ in range(int(rng.integers(2, 6))):
        kind = ("red cylinder", "blue cylinder", "red box", "blue box", "above", "beside", "poster", "patch")[
            int(rng.integers(8))
        ]
        x, z = spot()
        if kind.endswith("cylinder"):
            cyl.append(
                Cylinder(x, z, d.uniform(rng, 0.012, 0.05), 0.0, d.uniform(rng, 0.03, 0.16), paint(kind.split()[0]))
            )
        elif kind.endswith("box"):
            box.append(
                Box(
                    x,
                    z,
                    d.uniform(rng, 0.03, 0.12),
                    d.uniform(rng, 0.03, 0.12),
                    0.0,
                    d.uniform(rng, 0.03, 0.15),
                    paint(kind.split()[0]),
                )
            )
        elif kind == "above":  # a red box high on a grey pedestal behind a blue cylinder
            top, w = d.uniform(rng, 0.30, 0.45), d.uniform(rng, 0.03, 0.05)
            box.append(Box(x, z, w * 0.6, w * 0.6, 0.0, top - 0.03, PEDESTAL))
            box.append(Box(x, z, w, w, top - 0.03, top, paint("red")))
            zb = z - d.uniform(rng, 0.1, 0.25)
            cyl.append(
                Cylinder(x * zb / z, zb, d.uniform(rng, 0.012, 0.02), 0.0, d.uniform(rng, 0.03, 0.06), paint("blue"))
            )
        elif kind == "beside":
            r = d.uniform(rng, 0.012, 0.025)
            gap = d.uniform(rng, 4.0, 8.0) * r * rng.choice([-1.0, 1.0])
            cyl.append(Cylinder(x, z, r, 0.0, d.uniform(rng, 0.05, 0.12), paint("red")))
            cyl.append(Cylinder(x + gap, z, r, 0.0, d.uniform(rng, 0.04, 0.1), paint("blue")))
        elif kind == "poster" and scene.wall_distance_m is not None:
            xw = -scene.wall_distance_m * math.tan(d.uniform(rng, -half, half))
            b, w = d.uniform(rng, 0.2, 0.35), d.uniform(rng, 0.1, 0.4)
            hgt = d.uniform(rng, 0.1, 0.3)
            posters.append(Poster(xw - w / 2, xw + w / 2, b, b + hgt, paint("red")))
        elif kind == "patch":
            w, dz = d.uniform(rng, 0.3, 1.2), d.uniform(rng, 0.3, 1.0)
            tint = PATCH_TINTS[int(rng.integers(len(PATCH_TINTS)))]
            patches.append(FloorPatch(x - w / 2, x + w / 2, z - dz / 2, z + dz / 2, d.jitter(rng, tint)))
    return dataclasses.replace(
        scene, cylinders=tuple(cyl), boxes=tuple(box), posters=tuple(posters), floor_patches=tuple(patches)
    )


def clutter_scene(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    """One ``clutter`` frame: no landmark or one, among distractors."""
    with_landmark = rng.random() < 0.5
    for _ in range(200):
        room = d.tinted_room(rng) if rng.random() < 0.5 else d.neutral_room(rng)
        base = Scene(
            camera=camera,
            lighting=d.lighting(rng, d.LIGHTS[int(rng.integers(5))]),
            imaging=d.imaging(rng),
            wall_distance_m=d.uniform(rng, 1.2, 2.5),
            **room,
        )
        lms: Tuple[LandmarkPose, ...] = ()
        if with_landmark:
            lm = d.draw_landmark(rng, base, lambda: d.log_uniform(rng, 0.25, 1.2))
            if lm is None:
                raise d.give_up("clutter", camera)
            lms = (lm,)
        scene = _distractors(rng, dataclasses.replace(base, landmarks=lms))
        if layout_ok(scene):
            return scene
    raise d.give_up("clutter", camera)
