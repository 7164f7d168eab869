"""The ArUco contender across OpenCV versions: DICT_4X4_50, default detector parameters.

OpenCV ≥ 4.7 (and 5.x) has ArUco in the main package with the class API
(``cv2.aruco.ArucoDetector``, ``generateImageMarker``). OpenCV 4.6 has it only
in ``opencv-contrib-python``, with the legacy functions (``detectMarkers``,
``drawMarker``, ``DetectorParameters_create``); plain ``opencv-python(-headless)``
4.6 has no ``cv2.aruco`` at all, and the benchmark then skips this contender.
"""

from __future__ import annotations

from typing import Callable, List, Optional, Sequence, Tuple

import cv2
import numpy as np

DICT_NAME = "DICT_4X4_50"


def available() -> bool:
    """Whether this OpenCV build has the ArUco module."""
    return hasattr(cv2, "aruco")


def _dictionary():
    aruco = cv2.aruco
    if hasattr(aruco, "getPredefinedDictionary"):
        return aruco.getPredefinedDictionary(aruco.DICT_4X4_50)
    return aruco.Dictionary_get(aruco.DICT_4X4_50)  # pragma: no cover - very old contrib builds


def marker_images(ids_and_sides: Sequence[Tuple[int, int]]) -> List[np.ndarray]:
    """Marker bitmaps (side×side uint8, black 0 / white 255) for ``(id, side_px)`` pairs.

    Without ArUco the bitmaps are blank white, so the frames still render.
    """
    if not available():
        return [np.full((side, side), 255, np.uint8) for _, side in ids_and_sides]
    aruco, d = cv2.aruco, _dictionary()
    draw = getattr(aruco, "generateImageMarker", None) or aruco.drawMarker  # ≥ 4.7 | 4.6 contrib
    return [draw(d, ident, side) for ident, side in ids_and_sides]


def make_detector() -> Callable[[np.ndarray], Optional[np.ndarray]]:
    """``detect(bgr) -> ids`` (N×1 int32 or None), grey conversion included."""
    aruco = cv2.aruco
    d = _dictionary()
    if hasattr(aruco, "ArucoDetector"):  # OpenCV ≥ 4.7
        detector = aruco.ArucoDetector(d, aruco.DetectorParameters())

        def detect(bgr: np.ndarray) -> Optional[np.ndarray]:
            gray = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
            _corners, ids, _rejected = detector.detectMarkers(gray)
            return ids

        return detect
    params = aruco.DetectorParameters_create()  # OpenCV 4.6 contrib

    def detect_legacy(bgr: np.ndarray) -> Optional[np.ndarray]:
        gray = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
        _corners, ids, _rejected = aruco.detectMarkers(gray, d, parameters=params)
        return ids

    return detect_legacy
