"""Per-pixel rays, distortion, projection and image extents."""

from __future__ import annotations

import dataclasses
import math

import cv2
import numpy as np
import pytest

from rangebearing.core.types import CameraIntrinsics
from rangebearing.errors import SceneError
from rangebearing.synth import LandmarkPose, Lighting, Scene, landmark_bbox_px, project, ray_grid, render_linear
from rangebearing.synth.camera import inside_image
from rangebearing.synth.sampling import bearing_limits

from .reference import band_weights, centroid

CAM = CameraIntrinsics()
DISTORTIONS = [(-0.30, 0.10, 0.0, 0.0, 0.0), (0.15, -0.05, 0.001, -0.002, 0.01),
               (-0.2, 0.05, 0.0, 0.0)]


def k_matrix(cam: CameraIntrinsics) -> np.ndarray:
    return np.array([[cam.fx_px, 0, cam.cx_px], [0, cam.fy_px, cam.cy_px], [0, 0, 1.0]])


def undistort(cam: CameraIntrinsics, uv: np.ndarray) -> np.ndarray:
    """OpenCV's undistortion, iterated to convergence on either OpenCV 4 or 5."""
    pts = np.asarray(uv, float).reshape(-1, 1, 2)
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 200, 1e-14)
    dist = np.array(cam.distortion)
    if hasattr(cv2, "undistortPointsIter"):
        out = cv2.undistortPointsIter(pts, k_matrix(cam), dist, None, None, crit)
    else:
        out = cv2.undistortPoints(pts, k_matrix(cam), dist, criteria=crit)
    return out.reshape(-1, 2)


def test_pinhole_grid_is_exact():
    g = ray_grid(CAM)
    assert g.x.shape == (480, 640)
    assert g.x[0, 0] == -319.5 / 634 and g.y[479, 639] == 239.5 / 634
    assert g.x[100, int(CAM.cx_px + 0.5) - 1] < 0 < g.x[100, int(CAM.cx_px + 0.5)]
    np.testing.assert_array_equal(g.jxx, 1 / 634)
    np.testing.assert_array_equal(g.jxy, 0)


def test_grid_is_cached_and_read_only():
    g = ray_grid(CAM)
    assert ray_grid(CameraIntrinsics()) is g
    with pytest.raises(ValueError):
        g.x[0, 0] = 1.0


@pytest.mark.parametrize("dist", DISTORTIONS)
def test_distorted_rays_reproject_onto_their_pixels(dist):
    cam = dataclasses.replace(CAM.scaled(160, 120), distortion=dist)
    g = ray_grid(cam)
    assert not np.isnan(g.x).any()
    rays = np.stack([g.x, g.y, np.ones_like(g.x)], -1).reshape(-1, 1, 3)
    uv, _ = cv2.projectPoints(rays, np.zeros(3), np.zeros(3), k_matrix(cam), np.array(dist))
    v, u = np.mgrid[0:120, 0:160]
    np.testing.assert_allclose(uv[:, 0, 0], u.ravel(), atol=1e-7)
    np.testing.assert_allclose(uv[:, 0, 1], v.ravel(), atol=1e-7)


@pytest.mark.parametrize("dist", DISTORTIONS)
def test_sub_pixel_rays_agree_with_opencv_undistortion(dist):
    cam = dataclasses.replace(CAM, distortion=dist)
    g = ray_grid(cam)
    rows, cols = np.array([0, 5, 240, 400, 479]), np.array([0, 630, 320, 17, 639])
    du, dv = 0.37, -0.42
    ours_x = g.x[rows, cols] + g.jxx[rows, cols] * du + g.jxy[rows, cols] * dv
    ours_y = g.y[rows, cols] + g.jyx[rows, cols] * du + g.jyy[rows, cols] * dv
    cv = undistort(cam, np.stack([cols + du, rows + dv], -1))
    np.testing.assert_allclose(ours_x * cam.fx_px, cv[:, 0] * cam.fx_px, atol=2e-3)
    np.testing.assert_allclose(ours_y * cam.fy_px, cv[:, 1] * cam.fy_px, atol=2e-3)


def test_project_inverts_the_grid_and_is_nan_behind():
    cam = dataclasses.replace(CAM, distortion=DISTORTIONS[0])
    g = ray_grid(cam)
    z = 0.8
    u, v = project(cam, 0.1, g.x[::40, ::40] * z, 0.1 - g.y[::40, ::40] * z, np.full((12, 16), z))
    vv, uu = np.mgrid[0:480:40, 0:640:40]
    np.testing.assert_allclose(u, uu, atol=1e-7)
    np.testing.assert_allclose(v, vv, atol=1e-7)
    assert np.isnan(project(CAM, 0.1, np.array([0.0]), np.array([0.1]), np.array([-1.0]))[0]).all()


def test_unsupported_distortion_is_a_config_error():
    with pytest.raises(SceneError, match="coefficients"):
        ray_grid(dataclasses.replace(CAM, distortion=(0.1,) * 12))


def test_distorted_render_undistorts_back_to_the_pinhole_bearing():
    # a detector that undistorts band centroids with OpenCV recovers the bearing
    # (to second order in the band's size: 0.3 px at 0.5 m, 0.06 px at 1.2 m here)
    lm = LandmarkPose(2.0, 0.3)
    flat = Lighting(ambient=1.0, exposure=1.0)
    cam = dataclasses.replace(CAM, distortion=DISTORTIONS[0])

    def red_and_blue(camera):
        scene = Scene(camera=camera, landmarks=(lm,), lighting=flat, wall_distance_m=None)
        lin = render_linear(scene)
        return np.array([centroid(band_weights(lin, "red")), centroid(band_weights(lin, "blue"))])

    pinhole, distorted = red_and_blue(CAM), red_and_blue(cam)
    assert np.abs(distorted - pinhole)[:, 0].min() > 5  # distortion really moved the image
    recovered = undistort(cam, distorted) * [cam.fx_px, cam.fy_px] + [cam.cx_px, cam.cy_px]
    np.testing.assert_allclose(recovered, pinhole, atol=0.05)


def test_landmark_bbox_and_bearing_limits():
    scene = Scene()
    lo, hi = bearing_limits(CAM, 0.5, 0.0175, margin_px=3.0)
    assert lo == pytest.approx(-hi, abs=1e-3)  # cx is half a pixel left of the middle
    at_left = landmark_bbox_px(scene, LandmarkPose(0.5, hi))
    assert at_left[0] == pytest.approx(3.0 - 0.5, abs=0.03)
    assert inside_image(CAM, at_left, 2.9) and not inside_image(CAM, at_left, 3.1)
    centre = landmark_bbox_px(scene, LandmarkPose(0.5, 0.0))
    half_w = CAM.fx_px * math.tan(math.asin(0.0175 / 0.5))
    assert centre[0] == pytest.approx(CAM.cx_px - half_w, abs=0.01)
    assert landmark_bbox_px(scene, LandmarkPose(0.5, math.pi)) is None  # behind the camera
