"""Random scenes for tests, benchmarks and demos, one preset per question asked.

``paper``    one landmark where the paper measured: d_v 0.28–0.72 m, |θ| ≤ 25°.
``wide``     one landmark anywhere it is wholly visible, 0.15–2 m, hard rooms and light.
``clutter``  red and blue distractors; half the frames hold no landmark.
``multi``    2–4 landmarks, 0.2–1.5 m, image extents apart (none occludes another).
``sample``   two neighbours moving smoothly, as in a short recorded clip (30 fps).

These five draw landmarks wholly inside the frame, unhidden, on plain dark
cylinders, under plain light, and render exactly as they always have for the
same seed. The crowd-proof presets put Zumo-like robots under the landmarks,
let them hide each other (the truth gives each band's visible fraction) and run
an auto-exposed Bayer camera:

``occlusion``  2–4 robots, one right behind another, a box in front now and then.
``touching``   landmarks against each other and against red and blue walls,
               boxes, mats, posters and objects; one frame in eight empty.
``crowd``      5–8 robots, some cut by the frame edges.
``far``        one robot 0.15–2.0 m anywhere wholly in view, any light.
``lighting``   1–3 robots under dim, bright, warm, cool, coloured, spotlit or
               backlit light.
``crowd-moving`` 4–6 robots driving and crossing at 30 fps, each with its
               ``robot_id`` (see :mod:`.motion`).

The photoreal presets (:mod:`.photoreal`) put those scenes through the Pi
Camera v1's lens and ISP and richer rooms: ``photoreal``, ``photoreal-crowd``;
``photoreal-alt`` (:mod:`.photoreal_alt`) through another camera and other paint.
``mimic`` (:mod:`.mimics`): red/white/blue things that are no landmark (flags, a red cup on a
white box on a blue mat, striped cans, a room's own stripes).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import Iterator, List, Tuple

import numpy as np

from .._compat import frozen
from ..core.types import CameraIntrinsics
from ..errors import SceneError
from . import sampling as d
from .camera import landmark_bbox_px
from .clutter import clutter_scene
from .crowd import crowd_scene, far_scene, lighting_scene, occlusion_scene, rooms_scene
from .mimics import MIMIC_HELP, MIMIC_PRESET, mimic_scene
from .motion import crowd_sequence
from .photoreal import PHOTOREAL_HELP, PHOTOREAL_PRESETS, photoreal_scene, photoreal_sequence
from .photoreal_alt import ALT_HELP, ALT_PRESET, alt_scene
from .scene import DEFAULT_CAMERA, LandmarkPose, Scene
from .touching import touching_scene

ORIGINAL_PRESETS = ("paper", "wide", "clutter", "multi", "sample")
CROWD_PRESETS = ("occlusion", "touching", "crowd", "far", "lighting", "crowd-moving", "rooms")
PRESETS = ORIGINAL_PRESETS + CROWD_PRESETS + PHOTOREAL_PRESETS + (ALT_PRESET, MIMIC_PRESET)
SAMPLE_FPS = 30.0
PRESET_HELP = {
    "paper": "one landmark at d_v 0.28-0.72 m, |bearing| <= 25 deg",
    "wide": "0.15-2 m anywhere in view, tinted rooms, dim/bright/warm/cool light",
    "clutter": "red/blue distractors, half the frames without a landmark",
    "multi": "2-4 landmarks, apart in the image",
    "sample": "two neighbours moving smoothly at 30 fps",
    "occlusion": "2-4 Zumo-like robots, some landmarks partly behind others or a box",
    "touching": "landmarks touching each other and red/blue walls, boxes, mats, posters; "
                "1 frame in 8 empty",
    "crowd": "5-8 robots in view, some cut by the frame edges",
    "far": "one robot 0.15-2.0 m over the whole field of view, any light",
    "lighting": "1-3 robots under dim, bright, warm, cool, coloured, spotlit or backlit light",
    "rooms": "lighting frames in a red room (carpet, brick) or a blue one (navy carpet, blue walls)",
    "crowd-moving": "4-6 robots driving about and crossing each other at 30 fps; truth.csv's "
                    "robot column keeps each robot's identity",
    **PHOTOREAL_HELP,
    **ALT_HELP,
    **MIMIC_HELP,
}


def _paper(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    base = Scene(camera=camera, lighting=d.lighting(rng), imaging=d.imaging(rng),
                 **d.neutral_room(rng))
    for _ in range(500):
        d_v, theta = d.uniform(rng, 0.28, 0.72), math.radians(d.uniform(rng, -25.0, 25.0))
        lm = LandmarkPose(d_v / math.cos(theta), theta)
        if d.in_view(base, lm):
            scene = dataclasses.replace(base, landmarks=(lm,))
            return d.with_wall_behind(scene, rng, 0.15, 0.65)
    raise d.give_up("paper", camera)


def _wide(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    kind = d.LIGHTS[int(rng.integers(len(d.LIGHTS)))]
    noise = {"dim": 2.5, "bright": 0.7}.get(kind, 1.0)
    base = Scene(camera=camera, camera_height_m=d.uniform(rng, 0.09, 0.11),
                 lighting=d.lighting(rng, kind), imaging=d.imaging(rng, noise, (0.0, 1.0)),
                 **d.tinted_room(rng))
    lm = d.draw_landmark(rng, base, lambda: d.log_uniform(rng, 0.15, 2.0), base_spread_m=0.02,
                         attempts=1000)
    if lm is None:
        raise d.give_up("wide", camera)
    return d.with_wall_behind(dataclasses.replace(base, landmarks=(lm,)), rng, 0.3, 1.5, 0.25)


def _apart(scene: Scene, lm: LandmarkPose, placed: List[LandmarkPose], gap_px: float) -> bool:
    box = landmark_bbox_px(scene, lm, with_robot=True)
    if box is None:
        return False
    for other in placed:
        ob = landmark_bbox_px(scene, other, with_robot=True)
        if ob is None or min(box[2], ob[2]) - max(box[0], ob[0]) > -gap_px:
            return False
    return True


def _multi(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    n = int(rng.integers(2, 5))
    kind = ("normal", "normal", "warm", "cool")[int(rng.integers(4))]
    room = d.tinted_room(rng) if rng.random() < 0.5 else d.neutral_room(rng)
    base = Scene(camera=camera, lighting=d.lighting(rng, kind), imaging=d.imaging(rng), **room)
    for _ in range(300):
        placed: List[LandmarkPose] = []
        for _ in range(n):
            lm = d.draw_landmark(rng, base, lambda: d.log_uniform(rng, 0.2, 1.5), 0.01,
                                 accept=lambda c, p=placed: _apart(base, c, p, 4.0), attempts=40)
            if lm is None:
                break
            placed.append(lm)
        if len(placed) == n:
            placed.sort(key=lambda lm: -lm.bearing_rad)  # left to right in the image
            scene = dataclasses.replace(base, landmarks=tuple(placed))
            return d.with_wall_behind(scene, rng, 0.3, 1.0)
    raise d.give_up("multi", camera)


@frozen
class Wander:
    """One neighbour's smooth path: range and bearing each a sinusoid of time."""

    range_m: float
    range_amp_m: float
    range_period_s: float
    range_phase_rad: float
    bearing_rad: float
    bearing_amp_rad: float
    bearing_period_s: float
    bearing_phase_rad: float

    def pose(self, t_s: float) -> LandmarkPose:
        r = self.range_m + self.range_amp_m * math.sin(
            2 * math.pi * t_s / self.range_period_s + self.range_phase_rad)
        b = self.bearing_rad + self.bearing_amp_rad * math.sin(
            2 * math.pi * t_s / self.bearing_period_s + self.bearing_phase_rad)
        return LandmarkPose(r, b)


def _wander(rng: np.random.Generator, side: float) -> Wander:
    # ranges 0.40–0.85 m and |bearing| 0.15–0.35 rad keep the two robots' image
    # extents apart and both landmarks inside a 640x480 frame at fx = 634.
    u = functools.partial(d.uniform, rng)
    return Wander(u(0.55, 0.70), u(0.05, 0.15), u(4.0, 7.0), u(0.0, 2 * math.pi),
                  side * u(0.22, 0.28), u(0.03, 0.07), u(3.0, 6.0), u(0.0, 2 * math.pi))


def sample_plan(rng: np.random.Generator, camera: CameraIntrinsics = DEFAULT_CAMERA
                ) -> Tuple[Scene, Tuple[Wander, ...]]:
    """The fixed part of a ``sample`` clip and the paths of its two neighbours."""
    base = Scene(camera=camera, lighting=d.lighting(rng), imaging=d.imaging(rng, 1.0, (0.4, 0.7)),
                 wall_distance_m=d.uniform(rng, 1.1, 1.5), **d.neutral_room(rng))
    return base, (_wander(rng, 1.0), _wander(rng, -1.0))


def sample_scene(base: Scene, paths: Tuple[Wander, ...], t_s: float) -> Scene:
    """The ``sample`` clip at time ``t_s``: the neighbours wholly in view at that moment."""
    poses = tuple(p.pose(t_s) for p in paths)
    visible = tuple(lm for lm in poses if d.in_view(base, lm, 0.0))
    return dataclasses.replace(base, landmarks=visible)


_NEWER = {"occlusion": occlusion_scene, "touching": touching_scene, "crowd": crowd_scene,
          "far": far_scene, "lighting": lighting_scene, "rooms": rooms_scene, MIMIC_PRESET: mimic_scene}


def random_scene(rng: np.random.Generator, preset: str,
                 camera: CameraIntrinsics = DEFAULT_CAMERA) -> Scene:
    """Draw one scene of a preset (see the module docstring).

    Parameters
    ----------
    rng : numpy.random.Generator
        The only source of randomness; the same state gives the same scene.
    preset : str
        One of :data:`PRESETS`.
    camera : CameraIntrinsics
        Placement keeps every landmark wholly inside this camera's frame.

    Raises
    ------
    SceneError
        Unknown preset, or a camera too small to place the landmarks in.
    """
    if preset == "paper":
        return _paper(rng, camera)
    if preset == "wide":
        return _wide(rng, camera)
    if preset == "clutter":
        return clutter_scene(rng, camera)
    if preset == "multi":
        return _multi(rng, camera)
    if preset == "sample":
        base, paths = sample_plan(rng, camera)
        return sample_scene(base, paths, d.uniform(rng, 0.0, 60.0))
    if preset in _NEWER:
        return _NEWER[preset](rng, camera)
    if preset == "crowd-moving":
        return next(crowd_sequence(rng, 1, camera))
    if preset in PHOTOREAL_PRESETS:
        return photoreal_scene(rng, preset, camera)
    if preset == ALT_PRESET:
        return alt_scene(rng, camera)
    raise SceneError([f"unknown preset {preset!r} (known: {', '.join(PRESETS)})"], "synth")


def scene_sequence(rng: np.random.Generator, preset: str, frames: int,
                   camera: CameraIntrinsics = DEFAULT_CAMERA) -> Iterator[Scene]:
    """``frames`` scenes: independent draws, or consecutive 30 fps moments for
    ``sample`` and ``crowd-moving``."""
    if preset == "crowd-moving":
        yield from crowd_sequence(rng, frames, camera)
        return
    if preset in PHOTOREAL_PRESETS:
        yield from photoreal_sequence(rng, preset, frames, camera)
        return
    if preset != "sample":
        for _ in range(frames):
            yield random_scene(rng, preset, camera)
        return
    base, paths = sample_plan(rng, camera)
    t0 = d.uniform(rng, 0.0, 60.0)
    for i in range(frames):
        yield sample_scene(base, paths, t0 + i / SAMPLE_FPS)
