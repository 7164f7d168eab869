"""Intrinsics from rendered chessboards with known camera, distortion and poses."""

import cv2
import numpy as np
import pytest

from rangebearing.core.intrinsics import board_points, coverage_problems, find_corners, fit_intrinsics
from rangebearing.core.types import CameraIntrinsics
from rangebearing.errors import CalibrationError
from rangebearing.synth.chessboard import camera_matrix, random_views, render_board

TRUE = CameraIntrinsics(640, 480, 560.0, 556.0, 322.0, 236.5, (-0.28, 0.09, 0.001, -0.0008, 0.0))
COLS, ROWS, SQ = 9, 6, 0.025


@pytest.fixture(scope="module")
def views():
    return random_views(TRUE, COLS, ROWS, SQ, 12, seed=3)


@pytest.fixture(scope="module")
def corners(views):
    found = [find_corners(cv2.cvtColor(v.image, cv2.COLOR_BGR2GRAY), COLS, ROWS) for v in views]
    assert all(c is not None for c in found)
    return found


def test_corners_found_to_a_tenth_of_a_pixel(views, corners):
    err = np.concatenate([np.linalg.norm(c - v.corners_px, axis=1) for c, v in zip(corners, views)])
    assert err.max() < 0.4
    assert err.mean() < 0.1


def test_fit_recovers_focal_lengths_and_distortion(views, corners):
    fit = fit_intrinsics(corners, COLS, ROWS, SQ, (640, 480))
    cam = fit.camera
    assert cam.fx_px == pytest.approx(TRUE.fx_px, rel=0.005)
    assert cam.fy_px == pytest.approx(TRUE.fy_px, rel=0.005)
    assert cam.cx_px == pytest.approx(TRUE.cx_px, abs=2.0)
    assert cam.cy_px == pytest.approx(TRUE.cy_px, abs=2.0)
    assert fit.rms_px < 0.2
    # the fitted model (distortion applied back) puts every true corner where it is
    k, d = camera_matrix(cam), np.asarray(cam.distortion)
    obj = board_points(COLS, ROWS, SQ)
    for v, rv, tv in zip(views, fit.rvecs, fit.tvecs):
        proj, _ = cv2.projectPoints(obj, np.array(rv), np.array(tv), k, d)
        assert np.abs(proj.reshape(-1, 2) - v.corners_px).max() < 0.2


def test_an_undistorted_fit_is_worse_than_the_real_model(corners):
    # sanity: the distortion matters in these frames, so the test above tests something
    obj = board_points(COLS, ROWS, SQ)
    img = [c.reshape(-1, 1, 2).astype(np.float32) for c in corners]
    fix = cv2.CALIB_FIX_K1 | cv2.CALIB_FIX_K2 | cv2.CALIB_FIX_K3 | cv2.CALIB_ZERO_TANGENT_DIST
    rms, *_ = cv2.calibrateCamera([obj] * len(img), img, (640, 480), None, None, flags=fix)
    assert rms > 1.0


def test_too_few_views_are_refused(corners):
    with pytest.raises(CalibrationError, match="too few views"):
        fit_intrinsics(corners[:4], COLS, ROWS, SQ, (640, 480))


def test_face_on_centred_views_are_refused_with_every_reason():
    obj = board_points(COLS, ROWS, SQ)
    flat = []
    for i in range(9):
        t = np.array([-0.1 + 0.004 * i, -0.06, 0.55])
        flat.append(cv2.projectPoints(obj, np.zeros(3), t, camera_matrix(TRUE), None)[0].reshape(-1, 2))
    problems = coverage_problems(flat, obj, (640, 480))
    assert any("not spread" in p for p in problems)
    assert any("tilt" in p for p in problems)
    assert not any("too few" in p for p in problems)


def test_a_frame_without_the_board_gives_none():
    blank = render_board(TRUE, COLS, ROWS, SQ, np.zeros(3), np.array([0.0, 0.0, -1.0]))  # board behind the camera
    assert find_corners(cv2.cvtColor(blank, cv2.COLOR_BGR2GRAY), COLS, ROWS) is None
