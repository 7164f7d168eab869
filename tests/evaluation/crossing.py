"""Rendered sequences of robots crossing each other in bearing, with a truth ``robot`` id per landmark."""

from __future__ import annotations

import dataclasses
from typing import Iterator, List, Sequence, Tuple

import numpy as np

from rangebearing.core.types import CameraIntrinsics
from rangebearing.evaluation.truth import TruthRow
from rangebearing.synth import looks
from rangebearing.synth.dataset import scene_truth
from rangebearing.synth.render import render
from rangebearing.synth.robots import robot

FPS = 30.0
CAMERA = CameraIntrinsics()

# (range from, range to, bearing from, bearing to) over the sequence
Path = Tuple[float, float, float, float]
# two robots crossing at different ranges: the near one passes in front of the far one and hides it
APART: Sequence[Path] = ((0.45, 0.50, 0.30, -0.30), (0.95, 0.90, -0.30, 0.30))
# two robots crossing at similar ranges: their bodies just clear each other, their landmarks touch
CLOSE: Sequence[Path] = ((0.62, 0.66, -0.25, 0.25), (0.74, 0.72, 0.25, -0.25))
# both at once, and the near robot of APART crossing the CLOSE pair too (a harder case, not a test)
CROSSINGS: Sequence[Path] = ((0.45, 0.50, 0.32, -0.30), (0.95, 0.90, -0.30, 0.32),
                             (0.62, 0.66, -0.05, 0.40), (0.74, 0.72, 0.42, -0.05))


def crossing_frames(frames: int, seed: int, paths: Sequence[Path] = CROSSINGS,
                    camera: CameraIntrinsics = CAMERA) -> Iterator[Tuple[float, np.ndarray, List[TruthRow]]]:
    """``(t_s, BGR image, truth rows)`` per frame at 30 fps; robot ``i`` moves linearly along ``paths[i]``."""
    rng = np.random.default_rng(seed)
    base = looks.base_scene(rng, camera, "normal")
    robots = [robot(rng, p[0], p[2], robot_id=i) for i, p in enumerate(paths)]
    for k in range(frames):
        u = k / max(frames - 1, 1)
        poses = tuple(dataclasses.replace(r, range_m=p[0] + u * (p[1] - p[0]), bearing_rad=p[2] + u * (p[3] - p[2]))
                      for r, p in zip(robots, paths))
        scene = dataclasses.replace(base, landmarks=poses)
        name = f"{k:06d}.png"
        yield k / FPS, render(scene, rng), scene_truth(scene, name)
