"""Fixtures for the frame-source tests: the picamera2 fake and tiny recordings."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType
from typing import Iterator, List

import cv2
import numpy as np
import pytest

FAKES = Path(__file__).resolve().parent.parent / "fakes"


def _install_fake(name: str, monkeypatch: pytest.MonkeyPatch) -> ModuleType:
    """Put tests/fakes/<name> into sys.modules as ``name`` (undone after the test)."""
    init = FAKES / name / "__init__.py"
    spec = importlib.util.spec_from_file_location(
        name, init, submodule_search_locations=[str(init.parent)]
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, name, module)
    spec.loader.exec_module(module)
    return module


@pytest.fixture
def fake_picamera2(monkeypatch: pytest.MonkeyPatch) -> Iterator[ModuleType]:
    """A fresh fake ``picamera2`` (and ``libcamera``) in sys.modules for one test.

    ``fake.WORLD`` is the camera hardware: stall it, skip frames, set the producer.
    The real picamera2 is never imported.
    """
    _install_fake("libcamera", monkeypatch)  # picamera2 imports it
    fake = _install_fake("picamera2", monkeypatch)
    yield fake
    fake.shutdown()


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
