"""ChArUco frames with known intrinsics, distortion and poses: the board's own image mapped onto a plane.

The texture is OpenCV's ``CharucoBoard.generateImage`` at ``px_per_square``
pixels a square with one square of white margin; every sub-pixel sample takes
the texture pixel its ray lands on (see :mod:`.chessboard` for the rays), and
each output pixel is the mean of its ``s × s`` samples.
"""

from __future__ import annotations

from typing import Any, List

import cv2
import numpy as np

from ..core.types import CameraIntrinsics
from .chessboard import BACKGROUND, BLACK, WHITE, BoardView, camera_matrix, plane_box, plane_coords, random_pose


def board_texture(board: Any, px_per_square: int = 120) -> np.ndarray:
    """The board's image, (H, W) uint8, one square of white margin on every side."""
    nx, ny = board.getChessboardSize()
    size = ((nx + 2) * px_per_square, (ny + 2) * px_per_square)
    return board.generateImage(size, marginSize=px_per_square)


def render_charuco(
    cam: CameraIntrinsics, board: Any, texture: np.ndarray, rvec: np.ndarray, tvec: np.ndarray, s: int = 3
) -> np.ndarray:
    """The board under one pose, (H, W, 3) uint8 BGR, black and white mapped to the chessboard renderer's greys."""
    sq = board.getSquareLength()
    nx, ny = board.getChessboardSize()
    px_m = sq * (nx + 2) / texture.shape[1]
    grey = np.full((cam.height_px, cam.width_px), BACKGROUND)
    box = plane_box(cam, (-sq, -sq, (nx + 1) * sq, (ny + 1) * sq), rvec, tvec)
    if box is not None:
        r0, r1, c0, c1 = box
        x, y, facing = plane_coords(cam, box, rvec, tvec, s)
        with np.errstate(invalid="ignore"):
            tu, tv = x / px_m + texture.shape[1] / (nx + 2), y / px_m + texture.shape[0] / (ny + 2)
            inside = facing & (tu >= 0) & (tu < texture.shape[1]) & (tv >= 0) & (tv < texture.shape[0])
        iu = np.clip(np.nan_to_num(tu), 0, texture.shape[1] - 1).astype(np.int64)
        iv = np.clip(np.nan_to_num(tv), 0, texture.shape[0] - 1).astype(np.int64)
        level = BLACK + (WHITE - BLACK) * texture[iv, iu] / 255.0
        patch = np.where(inside, level, BACKGROUND)
        grey[r0:r1, c0:c1] = patch.reshape(r1 - r0, s, c1 - c0, s).mean(axis=(1, 3))
    return np.repeat(np.clip(grey + 0.5, 0, 255).astype(np.uint8)[:, :, None], 3, axis=2)


def random_charuco_views(
    cam: CameraIntrinsics, board: Any, n: int, seed: int = 0, max_tilt_deg: float = 35.0
) -> List[BoardView]:
    """``n`` views of the board; at least half its inner corners lie in the frame, the rest may not (partial views)."""
    rng = np.random.default_rng(seed)
    texture = board_texture(board)
    sq = board.getSquareLength()
    nx, ny = board.getChessboardSize()
    obj = np.asarray(board.getChessboardCorners(), np.float64)
    centre = np.array([nx * sq / 2, ny * sq / 2, 0.0])
    k, d = camera_matrix(cam), np.asarray(cam.distortion, np.float64)
    views: List[BoardView] = []
    while len(views) < n:
        rvec, t = random_pose(rng, cam, nx * sq, centre, max_tilt_deg)
        corners = cv2.projectPoints(obj, rvec, t, k, d)[0].reshape(-1, 2)
        inside = (corners[:, 0] >= 8) & (corners[:, 0] <= cam.width_px - 9) & (corners[:, 1] >= 8) & (
            corners[:, 1] <= cam.height_px - 9)
        if inside.mean() < 0.5:
            continue
        views.append(BoardView(render_charuco(cam, board, texture, rvec, t), rvec, t, corners))
    return views
