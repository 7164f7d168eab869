"""Fixtures for the frame-source tests: tiny recordings (the picamera2 fake is in tests/conftest.py)."""

from __future__ import annotations

from pathlib import Path
from typing import List

import cv2
import numpy as np
import pytest

from tests.sources.camera_fakes import alt_picamera2, camera  # noqa: F401  (fixtures: both picamera2 fakes)


def solid_bgr(value: int, height: int = 48, width: int = 64) -> np.ndarray:
    """A frame whose every pixel is ``value`` in all channels."""
    return np.full((height, width, 3), value, dtype=np.uint8)


def frame_brightness(image: np.ndarray) -> float:
    return float(image.mean())


@pytest.fixture
def tiny_video(tmp_path: Path) -> Path:
    """A 6-frame 64×48 MJPG .avi whose frame i has brightness 30·i + 20."""
    path = tmp_path / "tiny.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 10.0, (64, 48))
    if not writer.isOpened():
        pytest.skip("this OpenCV build cannot write MJPG .avi")
    for i in range(6):
        writer.write(solid_bgr(30 * i + 20))
    writer.release()
    return path


def video_levels() -> List[int]:
    return [30 * i + 20 for i in range(6)]
