"""The ``crowd-moving`` sequence: robots drive, cross, keep their identity."""

from __future__ import annotations

import math

import numpy as np

from rangebearing.core.types import CameraIntrinsics
from rangebearing.synth import generate, scene_sequence
from rangebearing.synth.motion import FPS

SMALL = CameraIntrinsics().scaled(320, 240)


def _run(seed: int, frames: int):
    return list(scene_sequence(np.random.default_rng(seed), "crowd-moving", frames))


def test_robots_keep_their_ids_and_move_smoothly_without_collisions():
    scenes = _run(3, 150)
    ids = [tuple(lm.robot_id for lm in s.landmarks) for s in scenes]
    assert len(set(ids)) == 1 and 4 <= len(ids[0]) <= 6 and ids[0] == tuple(range(len(ids[0])))
    x = np.array([[lm.x_m for lm in s.landmarks] for s in scenes])
    z = np.array([[lm.z_m for lm in s.landmarks] for s in scenes])
    step = np.hypot(np.diff(x, axis=0), np.diff(z, axis=0))
    assert step.max() <= 0.35 / FPS + 1e-9  # at most 0.35 m/s
    assert (step.sum(axis=0) > 0.3).all()  # every robot drives somewhere
    for s in scenes:
        for i, a in enumerate(s.landmarks):
            for b in s.landmarks[:i]:
                assert math.hypot(a.x_m - b.x_m, a.z_m - b.z_m) >= a.body.footprint_m + b.body.footprint_m


def test_robots_cross_each_other_in_the_image():
    scenes = _run(4, 240)
    b = np.array([[lm.bearing_rad for lm in s.landmarks] for s in scenes])
    crossings = sum(int((np.diff(np.sign(b[:, i] - b[:, j])) != 0).sum())
                    for i in range(b.shape[1]) for j in range(i))
    assert crossings >= 2


def test_truth_carries_the_robot_column_and_the_same_seed_the_same_run():
    a = [(rows, img) for _, img, rows in generate(3, 11, "crowd-moving", camera=SMALL)]
    b = [(rows, img) for _, img, rows in generate(3, 11, "crowd-moving", camera=SMALL)]
    assert all(ra == rb and np.array_equal(ia, ib) for (ra, ia), (rb, ib) in zip(a, b))
    robots = [r.robot for rows, _ in a for r in rows]
    assert robots and all(isinstance(r, int) and r >= 0 for r in robots)
