"""ChArUco targets: a chessboard with ArUco markers in its white squares, so partial views still count.

Each found corner carries its id, hence its place on the board: a view that
shows only part of the target (near the frame's edges, where distortion is
largest) still adds points, which plain chessboards cannot (all or nothing).
The fit is :func:`rangebearing.core.intrinsics.fit_views`.
"""

from __future__ import annotations

from typing import Any, Optional, Tuple

import cv2
import numpy as np

from ..errors import CalibrationError

MIN_CORNERS = 6  # fewer corners in one view pin no pose down


def dictionary_names() -> Tuple[str, ...]:
    """The predefined ArUco dictionaries this OpenCV has, as ``4X4_50`` etc."""
    return tuple(n[5:] for n in dir(cv2.aruco) if n.startswith("DICT_") and not n.startswith("DICT_APRILTAG"))


def charuco_board(squares_x: int, squares_y: int, square_m: float, marker_m: float, dictionary: str) -> Any:
    """A ``cv2.aruco.CharucoBoard`` of ``squares_x × squares_y`` squares (not inner corners).

    Raises
    ------
    CalibrationError
        An unknown dictionary name, markers not smaller than the squares, or a
        board with more markers than the dictionary holds.
    """
    name = f"DICT_{dictionary.upper()}"
    if not hasattr(cv2.aruco, name):
        raise CalibrationError(f"unknown ArUco dictionary {dictionary!r} (known: {', '.join(dictionary_names())})")
    if not 0 < marker_m < square_m:
        raise CalibrationError(f"markers ({marker_m * 1000:g} mm) must be smaller than the squares "
                               f"({square_m * 1000:g} mm)")
    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, name))
    needed = squares_x * squares_y // 2
    if needed > len(d.bytesList):
        raise CalibrationError(f"a {squares_x}x{squares_y} board needs {needed} markers; {dictionary} has "
                               f"{len(d.bytesList)}")
    return cv2.aruco.CharucoBoard((squares_x, squares_y), square_m, marker_m, d)


def find_charuco(gray: np.ndarray, board: Any) -> Optional[Tuple[np.ndarray, np.ndarray]]:
    """The board's inner corners seen in a frame: pixels (N, 2) float32 and board points (N, 3), or None.

    Parameters
    ----------
    gray : (H, W) uint8 array
    board : cv2.aruco.CharucoBoard
        From :func:`charuco_board`.

    Returns
    -------
    (image_points, object_points) or None
        None when fewer than :data:`MIN_CORNERS` corners are found.
    """
    corners, ids, _marker_corners, _marker_ids = cv2.aruco.CharucoDetector(board).detectBoard(gray)
    if ids is None or len(ids) < MIN_CORNERS:
        return None
    obj = np.asarray(board.getChessboardCorners(), np.float32)[np.ravel(ids)]
    return np.asarray(corners, np.float32).reshape(-1, 2), obj
