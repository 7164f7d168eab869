"""The AprilTag 3 contender (``pupil-apriltags``, tag36h11) and the tag bitmaps painted into the frames.

``pupil-apriltags`` is the benchmark's optional extra (``pip install -e '.[bench]'``);
without it the contender is skipped and the tables say so. The bitmaps come
from OpenCV's ``DICT_APRILTAG_36h11`` (the same codes and ids as the AprilTag
library; checked by ``tests/test_bench_smoke.py``), so frames render the same
whether or not the detector is installed.
"""

from __future__ import annotations

import atexit
from typing import Callable, List, Optional, Sequence, Tuple

import cv2
import numpy as np

FAMILY = "tag36h11"
DECIMATES = (2.0, 1.0)  # the library's default, and full resolution
_LIVE: list = []  # every detector made, kept until exit (see _never_destroy)


@atexit.register
def _never_destroy() -> None:
    """Leave the detectors to the OS at exit.

    ``Detector.__del__`` frees the tag family before the detector that still
    points into it and crashes the interpreter (SIGSEGV) now and then
    (pupil-labs/apriltags #34, #46); with no pointer it frees nothing.
    """
    for detector in _LIVE:
        detector.tag_detector_ptr = None


def available() -> bool:
    """Whether ``pupil_apriltags`` imports."""
    try:
        import pupil_apriltags  # noqa: F401
    except ImportError:
        return False
    return True


def version() -> str:
    try:
        from importlib.metadata import version as dist_version

        return dist_version("pupil-apriltags")
    except Exception:  # only for the report
        return "?"


def tag_images(ids_and_sides: Sequence[Tuple[int, int]]) -> List[np.ndarray]:
    """tag36h11 bitmaps (side×side uint8, black 0 / white 255) for ``(id, side_px)`` pairs.

    The bitmap is the tag's 8×8 cells (black border included); the white
    border a printed tag needs is the free wall the placement leaves around it.
    Without ``cv2.aruco`` the bitmaps are blank white.
    """
    if not hasattr(cv2, "aruco"):
        return [np.full((side, side), 255, np.uint8) for _, side in ids_and_sides]
    aruco = cv2.aruco
    d = aruco.getPredefinedDictionary(aruco.DICT_APRILTAG_36h11)
    draw = getattr(aruco, "generateImageMarker", None) or aruco.drawMarker
    return [draw(d, ident, side) for ident, side in ids_and_sides]


def make_detector(quad_decimate: float) -> Callable[[np.ndarray], Optional[List[int]]]:
    """``detect(bgr) -> tag ids``, one thread, grey conversion included."""
    from pupil_apriltags import Detector

    detector = Detector(families=FAMILY, nthreads=1, quad_decimate=quad_decimate)
    _LIVE.append(detector)

    def detect(bgr: np.ndarray) -> List[int]:
        gray = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
        return [d.tag_id for d in detector.detect(gray)]

    return detect
