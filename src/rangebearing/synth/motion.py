"""The ``crowd-moving`` preset: robots driving about in front of a parked camera, 30 fps.

4–6 Zumo-like robots drive in an arena ahead of the camera (0.25–1.8 m deep,
a little wider than the field of view, so they leave it and come back). Each
drives at its own speed (0.1–0.35 m/s) with a slowly wandering turn rate,
turns back towards the middle at the arena's edge, and, when it would come
too close to another robot, stops and turns away instead. Robots at different
depths cross each other in the image all the time, so landmarks pass behind
one another; every robot keeps its ``robot_id`` for the whole sequence.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Iterator, List, Tuple

import numpy as np

from .._compat import frozen
from ..core.types import CameraIntrinsics
from . import looks
from . import sampling as d
from .robots import OWN_FOOTPRINT_M, half_fov_rad, robot
from .scene import LandmarkPose, Scene

FPS = 30.0
DEPTH_M = (0.25, 1.8)
SIDE_MARGIN_M = 0.15


@frozen
class Driver:
    """One robot's state: position (x, z), heading, speed and turn rate."""

    x_m: float
    z_m: float
    heading_rad: float
    speed_mps: float
    turn_radps: float


def _pose(template: LandmarkPose, s: Driver) -> LandmarkPose:
    return dataclasses.replace(template, range_m=math.hypot(s.x_m, s.z_m),
                               bearing_rad=math.atan2(-s.x_m, s.z_m), heading_rad=s.heading_rad)


def _inside(x: float, z: float, half: float) -> bool:
    return DEPTH_M[0] <= z <= DEPTH_M[1] and abs(x) <= z * math.tan(half) + SIDE_MARGIN_M


def _free(x: float, z: float, i: int, states: List[Driver], feet: List[float]) -> bool:
    if math.hypot(x, z) < feet[i] + OWN_FOOTPRINT_M:
        return False
    return all(j == i or math.hypot(x - o.x_m, z - o.z_m) >= feet[i] + feet[j] + 0.01
               for j, o in enumerate(states))


def crowd_plan(rng: np.random.Generator, camera: CameraIntrinsics
               ) -> Tuple[Scene, List[LandmarkPose], List[Driver]]:
    """The parked camera's room and light, each robot's look and its starting state."""
    kind = looks.everyday(rng)
    base = looks.base_scene(rng, camera, kind)
    base = dataclasses.replace(base, wall_distance_m=DEPTH_M[1] + 0.1 + d.uniform(rng, 0.0, 0.8))
    half = half_fov_rad(camera)
    n = int(rng.integers(4, 7))
    templates: List[LandmarkPose] = []
    states: List[Driver] = []
    for _ in range(2000):
        if len(states) == n:
            break
        z = d.uniform(rng, DEPTH_M[0] + 0.1, DEPTH_M[1] - 0.1)
        x = d.uniform(rng, -1.0, 1.0) * z * math.tan(half)
        lm = robot(rng, math.hypot(x, z), math.atan2(-x, z), robot_id=len(states))
        feet = [t.body.footprint_m for t in templates] + [lm.body.footprint_m]  # type: ignore[union-attr]
        cand = Driver(x, z, lm.heading_rad, d.uniform(rng, 0.1, 0.35), 0.0)
        if _free(x, z, len(states), [*states, cand], feet):
            templates.append(lm)
            states.append(cand)
    if len(states) < n:
        raise d.give_up("crowd-moving", camera)
    return looks.finish(rng, base, kind), templates, states


def _step(rng: np.random.Generator, states: List[Driver], feet: List[float], half: float) -> List[Driver]:
    dt = 1.0 / FPS
    out = list(states)
    for i, s in enumerate(states):
        turn = float(np.clip(s.turn_radps + rng.normal(0.0, 0.15), -1.2, 1.2))
        heading = s.heading_rad + turn * dt
        x = s.x_m + s.speed_mps * dt * math.cos(heading)
        z = s.z_m + s.speed_mps * dt * math.sin(heading)
        if not _inside(x, z, half):  # head back towards the middle of the arena
            mid = (0.0, 0.5 * (DEPTH_M[0] + DEPTH_M[1]))
            heading = math.atan2(mid[1] - s.z_m, mid[0] - s.x_m) + rng.normal(0.0, 0.3)
            x, z = s.x_m, s.z_m
        if not _free(x, z, i, out, feet):  # stop, and turn away
            x, z = s.x_m, s.z_m
            heading = s.heading_rad + math.copysign(2.0, turn or 1.0) * dt * 4
        out[i] = Driver(x, z, heading, s.speed_mps, turn)
    return out


def crowd_sequence(rng: np.random.Generator, frames: int, camera: CameraIntrinsics
                   ) -> Iterator[Scene]:
    """``frames`` consecutive 30 fps moments of one ``crowd-moving`` run."""
    base, templates, states = crowd_plan(rng, camera)
    feet = [t.body.footprint_m if t.body else 0.05 for t in templates]
    half = half_fov_rad(camera)
    for _ in range(int(rng.integers(0, 60))):  # let them get going
        states = _step(rng, states, feet, half)
    for _ in range(frames):
        poses = tuple(_pose(t, s) for t, s in zip(templates, states))
        yield dataclasses.replace(base, landmarks=poses)
        states = _step(rng, states, feet, half)
