"""The ``mimic`` preset: landmark-like things that are no landmark, and never a landmark's double."""

import dataclasses

import numpy as np
import pytest

from rangebearing import Pipeline
from rangebearing.config import Config
from rangebearing.synth import random_scene, render
from rangebearing.synth.camera import cylinder_bbox_px, landmark_bbox_px
from rangebearing.synth.clutter import colour_class
from rangebearing.synth.mimics import GREY, KINDS
from rangebearing.synth.scene import BLUE_PAINT, RED_PAINT, WHITE_PAINT, Box, Cylinder, LandmarkPose, Poster, Scene


def draws(n, seed=0):
    rng = np.random.default_rng(seed)
    return [random_scene(rng, "mimic") for _ in range(n)]


def striped_cans(scene: Scene):
    """The scene's red/white/blue cans: groups of three stacked cylinders on one axis."""
    axes = {}
    for c in scene.cylinders:
        axes.setdefault((round(c.x_m, 6), round(c.z_m, 6), round(c.radius_m, 6)), []).append(c)
    return [sorted(g, key=lambda c: c.bottom_m) for g in axes.values() if len(g) == 3]


def test_mimic_frames_hold_mimics_empty_frames_and_landmarks():
    scenes = draws(60)
    assert all(s.posters or s.cylinders or s.boxes for s in scenes)
    empty = sum(not s.landmarks for s in scenes)
    assert 5 <= empty <= 30
    assert sum(bool(striped_cans(s)) for s in scenes) >= 5
    assert sum(any(colour_class(p.colour) == "red" for p in s.posters) for s in scenes) >= 5  # flags
    assert set(KINDS) == {"flag", "cup", "can", "stripes"}


def test_no_mimic_hides_or_touches_a_landmark_in_the_image():
    for s in draws(60, seed=1):
        things = [cylinder_bbox_px(s, c.x_m, c.z_m, c.radius_m, c.bottom_m, c.top_m) for c in s.cylinders]
        for lm in s.landmarks:
            lb = landmark_bbox_px(s, lm, with_robot=True)
            assert all(min(lb[2], b[2]) - max(lb[0], b[0]) <= -8.0 for b in things if b is not None)


def test_a_can_in_a_landmarks_proportions_is_no_scaled_landmark():
    # a landmark scaled as a whole images exactly as a nearer landmark: every can differs in one property
    g = Scene().geometry
    seen = 0
    for s in draws(80, seed=2):
        for blue, white, red in striped_cans(s):
            height = red.top_m - blue.bottom_m
            shares = [(c.top_m - c.bottom_m) / height for c in (blue, white, red)]
            landmark_shares = np.allclose(shares, [15 / 70, 40 / 70, 15 / 70], atol=1e-6)
            if landmark_shares:
                assert blue.radius_m >= 1.9 * g.radius_m and 0.75 * g.height_m <= height <= 1.3 * g.height_m
            seen += 1
    assert seen >= 5


def _stack(bottom, height, shares=(15 / 70, 40 / 70, 15 / 70)):
    blue, white = bottom + shares[0] * height, bottom + (shares[0] + shares[1]) * height
    return [(bottom, blue), (blue, white), (white, bottom + height)]


PAINTS = (BLUE_PAINT, WHITE_PAINT, RED_PAINT)


def flag(x_m, height_m, wall_m=1.0, width_m=0.6, shares=(15 / 70, 40 / 70, 15 / 70)):
    """A flag on the wall ``wall_m`` away, in the landmark's stripes (or ``shares``), centred at the camera's height."""
    stripes = tuple(Poster(x_m - width_m / 2, x_m + width_m / 2, lo, hi, p)
                    for (lo, hi), p in zip(_stack(0.1 - height_m / 2, height_m, shares), PAINTS))
    return Scene(wall_distance_m=wall_m, posters=stripes)


def can(z_m, widths, x_m=0.05):
    """A can in the landmark's stripes and of its height, ``widths`` landmarks wide, on a grey box."""
    r = Scene().geometry.radius_m * widths
    parts = tuple(Cylinder(x_m, z_m, r, lo, hi, p) for (lo, hi), p in zip(_stack(0.065, 0.07), PAINTS))
    return Scene(wall_distance_m=1.5, cylinders=parts, boxes=(Box(x_m, z_m, 2.2 * r, 2.2 * r, 0.0, 0.065, GREY),))


@pytest.mark.parametrize("scene", [flag(0.0, 0.21), flag(-0.2, 0.21), flag(0.25, 0.14), can(0.4, 2.2), can(0.6, 2.2),
                                   can(0.9, 3.0)],
                         ids=["flag-3x", "flag-3x-left", "flag-2x-right", "can-2.2", "can-2.2-at-0.6", "can-far"])
def test_a_wide_thing_in_the_landmarks_stripes_is_no_row_of_landmarks(scene):
    # its run is split into silhouettes of one size whose axes stand closer than two robots can
    got = Pipeline(Config().pipeline, track=False).process(render(scene, np.random.default_rng(0))).landmarks
    assert len(got) == 0


@pytest.mark.parametrize("scene", [can(0.4, 3.5, 0.04), can(0.55, 3.0, 0.055), can(0.9, 4.0, 0.09),
                                   can(1.2, 3.0, 0.12)],
                         ids=["can-3.5-at-0.4", "can-3-at-0.55", "can-4-at-0.9", "can-3-at-1.2"])
def test_a_fat_can_is_no_landmark_at_its_ends(scene):
    # its run is split into three silhouettes: the middle one nearer than the ends (its bands image taller,
    # rows 2-3 px apart though the centres agree), or found only by the second look, which drops a middle
    # piece cut on both sides: the ends, each with one limb of the can's, are its pieces too
    got = Pipeline(Config().pipeline, track=False).process(render(scene, np.random.default_rng(0))).landmarks
    assert len(got) == 0


@pytest.mark.parametrize("scene", [flag(0.14, 0.07, 1.4, 0.35), flag(-0.34, 0.07, 1.7, 0.35),
                                   flag(0.2, 0.07, 2.0, 0.21)],
                         ids=["flag-5x-at-1.4", "flag-5x-at-1.7-left", "flag-3x-at-2.0"])
def test_a_far_flag_is_no_row_of_landmarks(scene):
    # far away its silhouettes are a dozen pixels wide, their band rows alike to a tenth of a pixel: their
    # sizes say one depth, though the rows' whole tolerance (1.5 px each) would allow robots a body apart
    got = Pipeline(Config().pipeline, track=False).process(render(scene, np.random.default_rng(0))).landmarks
    assert len(got) == 0


@pytest.mark.parametrize("x_m", [-0.12, 0.06])
def test_a_flag_cut_into_overlapping_silhouettes_is_no_pair_of_landmarks(x_m):
    # a white flag with thin red and blue hems, little wider than tall: its run cut into two silhouettes that
    # overlap by half their width, their band rows alike (one depth): two landmarks cannot stand so
    scene = flag(x_m, 0.1, 0.6, 0.12, (0.075, 0.85, 0.075))
    got = Pipeline(Config().pipeline, track=False).process(render(scene, np.random.default_rng(0))).landmarks
    assert len(got) == 0


def test_a_landmark_beside_a_flag_is_still_found():
    scene = dataclasses.replace(flag(0.25, 0.21), landmarks=(LandmarkPose(0.5, 0.25),))
    got = Pipeline(Config().pipeline, track=False).process(render(scene, np.random.default_rng(0))).landmarks
    assert [round(lm.range_m, 1) for lm in got] == [0.5]
