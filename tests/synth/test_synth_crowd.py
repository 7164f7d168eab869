"""The crowd-proof presets: robots, occlusion, same-coloured surroundings, findable truth."""

from __future__ import annotations

import math
from typing import List

import numpy as np
import pytest

from rangebearing.core.types import CameraIntrinsics
from rangebearing.synth import Scene, generate, landmark_bbox_px, random_scene
from rangebearing.synth.camera import inside_image
from rangebearing.synth.clutter import colour_class
from rangebearing.synth.visibility import landmark_visibility

CAM = CameraIntrinsics()


def draws(preset: str, n: int, seed: int = 21) -> List[Scene]:
    rng = np.random.default_rng(seed)
    return [random_scene(rng, preset, CAM) for _ in range(n)]


def _robots_apart(scene: Scene) -> bool:
    lms = scene.landmarks
    for i, a in enumerate(lms):
        for b in lms[:i]:
            if math.hypot(a.x_m - b.x_m, a.z_m - b.z_m) < a.body.footprint_m + b.body.footprint_m:
                return False
    return True


def test_occlusion_hides_some_landmarks_partly_and_keeps_some_findable():
    scenes = draws("occlusion", 30)
    assert {len(s.landmarks) for s in scenes} == {2, 3, 4}
    partly = with_findable = 0
    for s in scenes:
        assert all(lm.body is not None for lm in s.landmarks) and _robots_apart(s)
        vis = landmark_visibility(s)
        with_findable += any(v.findable for v in vis)
        partly += any(0.05 < v.overall < 0.95 for v in vis)
    assert partly >= 10 and with_findable >= 25  # a box may hide the front one too
    assert any(s.boxes for s in scenes)  # a box in front of a landmark now and then


def test_crowd_has_five_to_eight_robots_some_cut_by_the_frame_edge():
    scenes = draws("crowd", 15)
    assert {len(s.landmarks) for s in scenes} <= set(range(5, 9))
    assert len({len(s.landmarks) for s in scenes}) >= 3
    findable = cut = 0
    for s in scenes:
        assert _robots_apart(s)
        vis = landmark_visibility(s)
        findable += sum(v.findable for v in vis)
        cut += sum(not inside_image(CAM, landmark_bbox_px(s, lm)) for lm in s.landmarks)
    assert findable >= 3 * len(scenes) and cut >= 3


def test_touching_puts_same_coloured_things_against_landmarks_and_has_empty_frames():
    scenes = draws("touching", 60)
    assert sum(not s.landmarks for s in scenes) >= 3
    walls = {colour_class(s.wall_colour) for s in scenes}
    assert {"red", "blue"} <= walls
    assert any(colour_class(p.colour) == "blue" for s in scenes for p in s.floor_patches)
    assert any(colour_class(b.colour) == "red" for s in scenes for b in s.boxes)
    assert any(p for s in scenes for p in s.posters)
    touching = 0
    for s in scenes:
        boxes = [landmark_bbox_px(s, lm) for lm in s.landmarks]
        touching += any(min(a[2], b[2]) - max(a[0], b[0]) > -1.0 for i, a in enumerate(boxes)
                        for b in boxes[:i])
        if s.landmarks:
            assert any(v.findable for v in landmark_visibility(s))
    assert touching >= 5


def test_far_covers_the_range_and_the_whole_field_of_view():
    scenes = draws("far", 120)
    r = np.array([s.landmarks[0].range_m for s in scenes])
    b = np.array([s.landmarks[0].bearing_rad for s in scenes])
    assert r.min() >= 0.15 and r.max() <= 2.0 and (r < 0.25).sum() >= 3 and (r > 1.5).sum() >= 3
    assert b.max() > 0.35 and b.min() < -0.35
    for s in scenes:
        assert inside_image(CAM, landmark_bbox_px(s, s.landmarks[0]), 2.99)
    assert all(landmark_visibility(s)[0].findable for s in scenes[:30])


def test_rooms_are_all_red_or_all_blue():
    scenes = draws("rooms", 12)
    kinds = set()
    for s in scenes:
        floor, wall = np.asarray(s.floor_colour), np.asarray(s.wall_colour)
        red = floor.argmax() == 0 and wall.argmax() == 0
        blue = floor.argmax() == 2 and wall.argmax() == 2
        assert red or blue  # both of one colour: the whole frame cast
        assert min(floor.max() / floor.min(), wall.max() / wall.min()) > 2.5
        kinds.add("red" if red else "blue")
        assert 1 <= len(s.landmarks) <= 3
    assert kinds == {"red", "blue"}


@pytest.mark.parametrize("preset", ["occlusion", "touching", "crowd", "far", "rooms"])
def test_frames_render_and_truth_lists_what_is_in_view(preset):
    small = CAM.scaled(320, 240)
    for _name, image, rows in generate(2, 5, preset, camera=small):
        assert image.shape == (240, 320, 3)
        for row in rows:
            assert 0.0 < row.visible <= 1.0 and row.findable == (
                row.red_visible >= 0.6 and row.blue_visible >= 0.6)
