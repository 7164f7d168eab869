"""Scene presets: ranges, visibility, variety, distractor rules, determinism."""

from __future__ import annotations

import math
from typing import List

import numpy as np
import pytest

from rangebearing.core.types import CameraIntrinsics
from rangebearing.errors import SceneError
from rangebearing.synth import (
    PRESETS,
    LandmarkPose,
    Scene,
    landmark_bbox_px,
    random_scene,
    render,
    scene_sequence,
)
from rangebearing.synth.camera import inside_image
from rangebearing.synth.clutter import colour_class, landmark_like, layout_ok, regions

from .reference import uint8_red_blue

CAM = CameraIntrinsics()


def draws(preset: str, n: int, seed: int = 11, camera: CameraIntrinsics = CAM) -> List[Scene]:
    rng = np.random.default_rng(seed)
    return [random_scene(rng, preset, camera) for _ in range(n)]


@pytest.mark.parametrize("preset", ("paper", "wide", "clutter", "multi", "sample", "far"))
def test_every_landmark_is_wholly_in_view_with_a_margin(preset):
    for scene in draws(preset, 60):
        for lm in scene.landmarks:
            box = landmark_bbox_px(scene, lm)
            assert inside_image(scene.camera, box, 2.99 if preset != "sample" else 0.0)
            if scene.wall_distance_m is not None:
                assert lm.z_m + scene.robot_radius_m < scene.wall_distance_m


def test_paper_range():
    scenes = draws("paper", 150)
    assert all(len(s.landmarks) == 1 for s in scenes)
    d_v = np.array([s.landmarks[0].z_m for s in scenes])
    theta = np.array([s.landmarks[0].bearing_rad for s in scenes])
    assert d_v.min() >= 0.28 and d_v.max() <= 0.72
    assert np.abs(theta).max() <= math.radians(25)
    assert d_v.min() < 0.32 and d_v.max() > 0.68 and np.abs(theta).max() > math.radians(20)
    assert all(s.lighting.wb_gains[0] == pytest.approx(1.0, abs=0.05) for s in scenes)


def test_wide_covers_both_ends_and_varied_light():
    scenes = draws("wide", 200)
    r = np.array([s.landmarks[0].range_m for s in scenes])
    assert r.min() >= 0.15 and r.max() <= 2.0
    assert (r < 0.25).sum() >= 5 and (r > 1.5).sum() >= 5
    theta = np.array([s.landmarks[0].bearing_rad for s in scenes])
    assert theta.max() > 0.4 and theta.min() < -0.4  # near the edges of the 53° field
    exposure = np.array([s.lighting.exposure for s in scenes])
    assert exposure.min() < 0.65 and exposure.max() > 2.0  # dim and over-exposed
    red_gain = np.array([s.lighting.wb_gains[0] for s in scenes])
    assert red_gain.min() < 0.85 and red_gain.max() > 1.15  # cool and warm
    bases = np.array([s.landmarks[0].base_height_m for s in scenes])
    assert 0.045 <= bases.min() < 0.055 and 0.075 < bases.max() <= 0.085
    assert len({s.floor_colour for s in scenes}) > 100
    assert any(s.wall_distance_m is None for s in scenes)


def test_clutter_has_empty_frames_distractors_and_no_landmark_like_pairs():
    scenes = draws("clutter", 80)
    counts = [len(s.landmarks) for s in scenes]
    assert set(counts) == {0, 1} and 20 < counts.count(0) < 60
    kinds = set()
    for s in scenes:
        assert layout_ok(s)
        found = regions(s)
        kinds |= {c for c, _ in found}
        reds = [b for c, b in found if c == "red"]
        blues = [b for c, b in found if c == "blue"]
        assert not any(landmark_like(r, b) for r in reds for b in blues)
        for lm in s.landmarks:
            assert 0.25 <= lm.range_m <= 1.2
    assert kinds == {"red", "blue"}
    assert any(s.posters for s in scenes) and any(s.floor_patches for s in scenes)
    # red boxes high on pedestals (misaligned "far above" pairs)
    assert any(b.bottom_m > 0.2 and colour_class(b.colour) == "red" for s in scenes for b in s.boxes)


def test_clutter_frames_without_a_landmark_still_show_red_and_blue():
    rng = np.random.default_rng(5)
    seen_red = seen_blue = 0
    for s in draws("clutter", 30, seed=5):
        if not s.landmarks:
            red, blue = uint8_red_blue(render(s, rng))
            seen_red += red.sum() > 0
            seen_blue += blue.sum() > 0
    assert seen_red >= 3 and seen_blue >= 3


def test_landmark_like_rule():
    # widths 20 px, red 30 px above blue: a landmark's proportions
    assert landmark_like((100, 100, 120, 110), (100, 130, 120, 140))
    assert not landmark_like((100, 100, 120, 110), (200, 130, 220, 140))  # side by side
    assert not landmark_like((100, 10, 120, 20), (100, 200, 120, 210))  # far above
    assert landmark_like((100, 130, 120, 140), (100, 100, 120, 110))  # blue on top: too close


def test_colour_class():
    assert colour_class((0.70, 0.07, 0.06)) == "red"
    assert colour_class((0.06, 0.12, 0.65)) == "blue"
    assert colour_class((0.6, 0.6, 0.6)) is None
    assert colour_class((0.40, 0.50, 0.36)) is None  # greenish floor


def test_multi_landmarks_are_apart_in_the_image():
    scenes = draws("multi", 60)
    assert {len(s.landmarks) for s in scenes} == {2, 3, 4}
    for s in scenes:
        boxes = sorted(landmark_bbox_px(s, lm, with_robot=True) for lm in s.landmarks)
        for a, b in zip(boxes, boxes[1:]):
            assert b[0] - a[2] >= 4.0
        for lm in s.landmarks:
            assert 0.2 <= lm.range_m <= 1.5


def test_sample_moves_smoothly():
    rng = np.random.default_rng(3)
    scenes = list(scene_sequence(rng, "sample", 90))
    assert all(len(s.landmarks) == 2 for s in scenes)
    for k in range(2):
        r = np.array([s.landmarks[k].range_m for s in scenes])
        b = np.array([s.landmarks[k].bearing_rad for s in scenes])
        assert np.abs(np.diff(r)).max() < 0.01 and np.abs(np.diff(b)).max() < 0.01
        assert np.ptp(r) > 0.005 or np.ptp(b) > 0.005  # it does move
    # everything but the neighbours stays put, as from a parked robot
    assert len({(s.floor_colour, s.wall_distance_m, s.lighting) for s in scenes}) == 1


def test_same_seed_same_scene_and_other_seed_other_scene():
    for preset in PRESETS:
        assert draws(preset, 3, seed=4) == draws(preset, 3, seed=4)
        assert draws(preset, 3, seed=4) != draws(preset, 3, seed=5)


def test_presets_follow_the_camera():
    small = CAM.scaled(320, 240)
    for scene in draws("wide", 20, camera=small):
        assert scene.camera == small
        assert inside_image(small, landmark_bbox_px(scene, scene.landmarks[0]), 2.99)


def test_unknown_preset_and_impossible_camera():
    with pytest.raises(SceneError, match="unknown preset"):
        random_scene(np.random.default_rng(0), "nope")
    tiny = CameraIntrinsics(width_px=8, height_px=6, fx_px=4.0, fy_px=4.0, cx_px=3.5, cy_px=2.5)
    with pytest.raises(SceneError, match="cannot place"):
        random_scene(np.random.default_rng(0), "paper", tiny)


def test_explicit_scene_validation():
    with pytest.raises(SceneError, match="range_m"):
        Scene(landmarks=(LandmarkPose(-1.0, 0.0),))
    with pytest.raises(SceneError, match="camera_height_m"):
        Scene(camera_height_m=0.0)
