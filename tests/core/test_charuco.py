"""ChArUco: corners with ids from rendered boards, partial views, and the fit."""

import cv2
import numpy as np
import pytest

from rangebearing.core.charuco import charuco_board, find_charuco
from rangebearing.core.intrinsics import fit_views
from rangebearing.core.types import CameraIntrinsics
from rangebearing.errors import CalibrationError
from rangebearing.synth.charuco import random_charuco_views

TRUE = CameraIntrinsics(640, 480, 560.0, 556.0, 322.0, 236.5, (-0.28, 0.09, 0.001, -0.0008, 0.0))


@pytest.fixture(scope="module")
def board():
    return charuco_board(10, 7, 0.025, 0.018, "4x4_50")


@pytest.fixture(scope="module")
def found(board):
    views = random_charuco_views(TRUE, board, 12, seed=2)
    return views, [find_charuco(cv2.cvtColor(v.image, cv2.COLOR_BGR2GRAY), board) for v in views]


def test_corners_carry_their_board_position(board, found):
    views, hits = found
    obj_all = np.asarray(board.getChessboardCorners(), np.float32)
    errs = []
    for v, hit in zip(views, hits):
        if hit is None:
            continue
        img, obj = hit
        ids = [int(np.flatnonzero((obj_all == o).all(axis=1))[0]) for o in obj]
        errs.append(np.linalg.norm(img - v.corners_px[ids], axis=1))
    err = np.concatenate(errs)
    assert len(errs) >= 10 and err.mean() < 0.2 and err.max() < 1.0  # OpenCV's ChArUco refinement
    assert min(len(h[0]) for h in hits if h is not None) < 54  # some views are partial, and still used


def test_fit_from_partial_views_recovers_the_camera(found):
    _views, hits = found
    ok = [h for h in hits if h is not None]
    fit = fit_views([h[0] for h in ok], [h[1] for h in ok], (640, 480))
    assert fit.camera.fx_px == pytest.approx(TRUE.fx_px, rel=0.005)
    assert fit.camera.fy_px == pytest.approx(TRUE.fy_px, rel=0.005)
    assert fit.rms_px < 0.3


def test_board_arguments_are_checked():
    with pytest.raises(CalibrationError, match="unknown ArUco dictionary 'ABC'"):
        charuco_board(10, 7, 0.025, 0.018, "ABC")
    with pytest.raises(CalibrationError, match="smaller than the squares"):
        charuco_board(10, 7, 0.025, 0.03, "4x4_50")
    with pytest.raises(CalibrationError, match="needs 55 markers"):
        charuco_board(11, 10, 0.025, 0.018, "4X4_50")
