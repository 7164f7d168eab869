"""The renderer: hand-checkable geometry, exactness against a reference, the sensor."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rangebearing.core.types import CameraIntrinsics
from rangebearing.synth import (
    Cylinder,
    Imaging,
    LandmarkPose,
    Lighting,
    Scene,
    landmark_bbox_px,
    render,
    render_linear,
)

from .reference import band_weights, centroid, reference_centroid, uint8_red_blue

CAM = CameraIntrinsics()
FLAT = Lighting(ambient=1.0, exposure=1.0)  # shading-free: weights are pure coverage
OPEN = dict(wall_distance_m=None)


def bands(linear: np.ndarray, scene: Scene, lm: LandmarkPose):
    """Red and blue centroids of one landmark, measured inside its image extent."""
    u0, v0, u1, v1 = landmark_bbox_px(scene, lm)
    mask = np.zeros(linear.shape[:2])
    mask[max(int(v0) - 2, 0) : int(v1) + 3, max(int(u0) - 2, 0) : int(u1) + 3] = 1
    return (centroid(band_weights(linear, "red") * mask),
            centroid(band_weights(linear, "blue") * mask))


def test_output_is_bgr_uint8_of_the_camera_size():
    cam = CameraIntrinsics().scaled(320, 240)
    img = render(Scene(camera=cam, landmarks=(LandmarkPose(0.5, 0.0),)))
    assert img.shape == (240, 320, 3) and img.dtype == np.uint8
    red, blue = uint8_red_blue(img)
    assert red.sum() > 0 and blue.sum() > 0  # red found in channel 2, blue in channel 0


def test_bearing_zero_projects_the_axis_to_column_cx():
    lm = LandmarkPose(0.5, 0.0)
    scene = Scene(landmarks=(lm,), lighting=FLAT, **OPEN)
    (rx, ry), (bx, by) = bands(render_linear(scene), scene, lm)
    assert rx == pytest.approx(CAM.cx_px, abs=0.01)
    assert bx == pytest.approx(CAM.cx_px, abs=0.01)
    assert ry < CAM.cy_px < by  # the camera (0.10 m) is between the bands


@pytest.mark.parametrize("theta_deg", [5.0, 15.0, 24.0])
def test_positive_bearing_appears_left_at_cx_minus_fx_tan(theta_deg):
    theta = math.radians(theta_deg)
    lm = LandmarkPose(0.6, theta)
    scene = Scene(landmarks=(lm,), lighting=FLAT, **OPEN)
    (rx, _), (bx, _) = bands(render_linear(scene), scene, lm)
    expected = CAM.cx_px - CAM.fx_px * math.tan(theta)
    assert rx < CAM.cx_px and bx < CAM.cx_px
    # the band's visible face is a little off the axis' projection; 1 px at 0.6 m
    assert rx == pytest.approx(expected, abs=1.0)
    assert bx == pytest.approx(expected, abs=1.0)


def test_negative_bearing_mirrors_positive():
    left, right = LandmarkPose(0.7, 0.2), LandmarkPose(0.7, -0.2)
    sl = Scene(landmarks=(left,), lighting=FLAT, **OPEN)
    sr = Scene(landmarks=(right,), lighting=FLAT, **OPEN)
    (lx, ly), _ = bands(render_linear(sl), sl, left)
    (rx, ry), _ = bands(render_linear(sr), sr, right)
    assert lx - CAM.cx_px == pytest.approx(-(rx - CAM.cx_px), abs=0.05)
    assert ly == pytest.approx(ry, abs=0.05)


@pytest.mark.parametrize("range_m", [0.3, 0.5, 1.0, 1.8])
def test_red_above_blue_and_band_spacing_follows_depth(range_m):
    lm = LandmarkPose(range_m, 0.1)
    scene = Scene(landmarks=(lm,), **OPEN)
    red, blue = uint8_red_blue(render(scene))
    (rx, ry), (bx, by) = centroid(red), centroid(blue)
    assert ry < by  # red on top: smaller row index
    assert rx == pytest.approx(bx, abs=0.5)  # one above the other
    spacing = by - ry
    assert spacing == pytest.approx(CAM.fy_px * 0.055 / lm.z_m, rel=0.07)
    # the visible face is nearer than the axis by about πR/4 (the model's c term)
    near = lm.z_m - math.pi / 4 * 0.0175
    assert spacing == pytest.approx(CAM.fy_px * 0.055 / near, rel=0.01)


@pytest.mark.parametrize("range_m, theta", [(0.2, 0.1), (0.45, -0.3), (0.9, 0.35), (2.0, -0.05)])
@pytest.mark.parametrize("lighting", [FLAT, Lighting()], ids=["flat", "lambert"])
def test_band_centroids_match_the_pixel_integrated_reference(range_m, theta, lighting):
    lm = LandmarkPose(range_m, theta)
    scene = Scene(landmarks=(lm,), lighting=lighting, **OPEN)
    red, blue = bands(render_linear(scene), scene, lm)
    ref_red, ref_blue = reference_centroid(scene, lm, "red"), reference_centroid(scene, lm, "blue")
    np.testing.assert_allclose(red, ref_red, atol=0.015)
    np.testing.assert_allclose(blue, ref_blue, atol=0.015)
    l_px = math.dist(red, blue)
    assert l_px == pytest.approx(math.dist(ref_red, ref_blue), rel=1e-3)


def test_supersampling_makes_sub_pixel_motion_smooth():
    # bearings 0.05 px apart: the centroid must follow them, in order, linearly
    step = math.atan(0.05 / CAM.fx_px)
    def track(supersample):
        xs = []
        for k in range(12):
            lm = LandmarkPose(1.2, 0.1 + k * step)
            scene = Scene(landmarks=(lm,), lighting=FLAT, **OPEN)
            xs.append(bands(render_linear(scene, supersample), scene, lm)[0][0])
        xs = np.array(xs)
        fit = np.polyval(np.polyfit(np.arange(12), xs, 1), np.arange(12))
        return xs, np.abs(xs - fit).max()
    xs, residual = track(4)
    assert np.all(np.diff(xs) < 0)  # bearing grows: the band moves left
    assert residual < 0.02
    _, aliased = track(1)
    assert aliased > 3 * residual


def test_nearer_object_occludes_farther_one():
    near, far = LandmarkPose(0.3, 0.0), LandmarkPose(1.5, 0.0)
    alone = render(Scene(landmarks=(near,)))
    both = render(Scene(landmarks=(near, far), wall_distance_m=3.0))
    behind_wall = render(Scene(landmarks=(near,), wall_distance_m=3.0))
    assert np.array_equal(both, behind_wall)
    assert not np.array_equal(alone, behind_wall)  # the wall moved: the test can fail
    # and a far landmark beside it is visible
    side = render(Scene(landmarks=(near, LandmarkPose(1.5, 0.3)), wall_distance_m=3.0))
    assert not np.array_equal(side, behind_wall)


def test_wall_hides_what_is_behind_it():
    lm = LandmarkPose(2.0, 0.0)
    assert uint8_red_blue(render(Scene(landmarks=(lm,), wall_distance_m=1.5)))[0].sum() == 0
    assert uint8_red_blue(render(Scene(landmarks=(lm,), wall_distance_m=2.5)))[0].sum() > 0


def test_red_distractor_is_red_and_opaque():
    scene = Scene(cylinders=(Cylinder(0.0, 0.5, 0.03, 0.0, 0.12, (0.7, 0.07, 0.06)),), lighting=FLAT)
    red, blue = uint8_red_blue(render(scene))
    assert red.sum() > 0 and blue.sum() == 0
    x, _ = centroid(red)
    assert x == pytest.approx(CAM.cx_px, abs=1.0)


def test_same_rng_state_gives_the_same_frame_and_noise_needs_an_rng():
    scene = Scene(landmarks=(LandmarkPose(0.5, 0.1),),
                  imaging=Imaging(blur_sigma_px=0.6, read_noise=0.01, shot_noise=0.002))
    a = render(scene, np.random.default_rng(7))
    b = render(scene, np.random.default_rng(7))
    c = render(scene, np.random.default_rng(8))
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)
    clean = render(scene)
    assert np.array_equal(clean, render(scene))
    assert 0.5 < np.abs(a.astype(int) - clean).mean() < 8


def test_exposure_and_white_balance():
    base = Scene(landmarks=(LandmarkPose(0.5, 0.0),))
    normal = render(base).astype(float)
    dim = render(dataclasses.replace(base, lighting=Lighting(exposure=0.4))).astype(float)
    bright = render(dataclasses.replace(base, lighting=Lighting(exposure=2.2)))
    warm = render(dataclasses.replace(base, lighting=Lighting(wb_gains=(1.25, 1.0, 0.75))))
    assert dim.mean() < 0.8 * normal.mean()
    assert (bright == 255).mean() > 0.2  # over-exposed walls clip
    wall = (10, 10)  # a wall pixel, BGR
    assert warm[wall][2] > normal[wall][2] and warm[wall][0] < normal[wall][0]


@settings(max_examples=15, deadline=None)
@given(range_m=st.floats(0.25, 1.5), frac=st.floats(-0.9, 0.9))
def test_band_centroid_column_tracks_bearing(range_m, frac):
    # anywhere in view, the band sits within a pixel of the axis' projection
    half = math.atan(CAM.cx_px / CAM.fx_px) - math.asin(0.0175 / range_m) - 0.01
    theta = frac * half
    lm = LandmarkPose(range_m, theta)
    scene = Scene(landmarks=(lm,), lighting=FLAT, **OPEN)
    (rx, _), (bx, _) = bands(render_linear(scene), scene, lm)
    expected = CAM.cx_px - CAM.fx_px * math.tan(theta)
    tol = 0.3 + CAM.fx_px * 0.0175**2 / (range_m * lm.z_m)  # second-order silhouette offset
    assert abs(rx - expected) < tol and abs(bx - expected) < tol


@pytest.mark.parametrize("range_m", [3.0, 6.0])
def test_far_landmark_bands_thinner_than_two_pixels_keep_their_area(range_m):
    lm = LandmarkPose(range_m, 0.05)
    scene = Scene(landmarks=(lm,), lighting=FLAT, **OPEN)
    lin = render_linear(scene)
    red_area = band_weights(lin, "red").sum() / (0.70 - 0.07)
    blue_area = band_weights(lin, "blue").sum() / (0.65 - 0.12)
    width = 2 * CAM.fx_px * math.tan(math.asin(0.0175 / range_m))
    expected = width * CAM.fy_px * 0.015 / lm.z_m
    assert red_area == pytest.approx(expected, rel=0.03)
    assert blue_area == pytest.approx(expected, rel=0.03)
