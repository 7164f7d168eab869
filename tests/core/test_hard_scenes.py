"""Situations issue 8 names, rendered with exact truth: the pipeline finds and measures each landmark."""

import dataclasses
import math

import numpy as np
import pytest

from rangebearing import Pipeline, load_config
from rangebearing.synth import Imaging, LandmarkPose, Scene, render
from rangebearing.synth.scene import Box, Cylinder, FloorPatch

NOISE = Imaging(blur_sigma_px=0.6, read_noise=0.004, shot_noise=0.0006)
RED_PAINT, BLUE_PAINT = (0.70, 0.07, 0.06), (0.06, 0.12, 0.65)


def scene(*lms, **kw):
    return Scene(landmarks=tuple(lms), imaging=NOISE, **{"wall_distance_m": 2.5, **kw})


def readings(sc, params=None):
    params = params or load_config(None).pipeline
    img = render(sc, np.random.default_rng(3))
    return sorted(Pipeline(params, track=False).process(img).landmarks, key=lambda lm: -lm.bearing_rad)


def assert_matches(found, truth, range_rel=0.01, bearing_deg=0.15):
    assert len(found) == len(truth)
    for lm, t in zip(found, sorted(truth, key=lambda t: -t.bearing_rad)):
        assert lm.range_m == pytest.approx(t.range_m, rel=range_rel)
        assert math.degrees(abs(lm.bearing_rad - t.bearing_rad)) <= bearing_deg


def test_a_landmark_beyond_the_calibrated_envelope_is_still_found_and_flagged():
    cfg = load_config(None).pipeline
    narrow = dataclasses.replace(cfg, model=dataclasses.replace(cfg.model, envelope_range_m=(0.2, 1.36)))
    truth = [LandmarkPose(2.0, 0.05)]
    (lm,) = readings(scene(*truth, wall_distance_m=3.0), narrow)
    assert_matches([lm], truth, range_rel=0.02)
    assert not lm.in_envelope


@pytest.mark.parametrize(
    "extra",
    [
        {"floor_colour": (0.05, 0.07, 0.25)},  # a navy carpet
        {"floor_patches": (FloorPatch(-0.5, 0.5, 0.3, 1.5, BLUE_PAINT),)},  # a blue mat under the robot
        {"boxes": (Box(0.0, 0.9, 0.2, 0.1, 0.09, 0.25, RED_PAINT),)},  # a red box right behind the band
        # a dark, faintly blue mast under the blue band
        {"cylinders": (Cylinder(-0.6 * math.sin(0.05), 0.6 * math.cos(0.05), 0.016, 0.0, 0.065, (0.03, 0.04, 0.09)),)},
    ],
    ids=["navy-carpet", "blue-mat", "red-box-behind", "bluish-mast"],
)
def test_coloured_surroundings_do_not_hide_or_pull_the_landmark(extra):
    truth = [LandmarkPose(0.6, 0.05 if "boxes" not in extra else 0.0)]
    assert_matches(readings(scene(*truth, **extra)), truth)


@pytest.mark.parametrize("range_m, half_gap_rad", [(0.6, 0.03), (1.2, 0.015)])
def test_two_landmarks_touching_in_the_image_are_both_measured(range_m, half_gap_rad):
    truth = [LandmarkPose(range_m, half_gap_rad), LandmarkPose(range_m, -half_gap_rad)]
    found = readings(scene(*truth))
    assert_matches(found, truth, bearing_deg=0.3)
    assert all(lm.visible == pytest.approx(1.0) for lm in found)


def test_a_landmark_half_behind_a_nearer_one_is_measured_from_what_is_visible():
    truth = [LandmarkPose(0.5, 0.0), LandmarkPose(0.9, 0.045)]
    near, far = sorted(readings(scene(*truth)), key=lambda lm: lm.range_m)
    assert near.range_m == pytest.approx(0.5, rel=0.01) and near.visible == pytest.approx(1.0)
    assert far.range_m == pytest.approx(0.9, rel=0.02) and 0.3 < far.visible < 0.9
    assert math.degrees(abs(far.bearing_rad - 0.045)) < 0.3
