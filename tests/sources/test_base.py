"""Frame, FrameSource, validate_frame and the open_source factory."""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from types import ModuleType
from typing import List

import cv2
import numpy as np
import pytest

from rangebearing.config import SourceConfig
from rangebearing.core.types import CameraIntrinsics
from rangebearing.errors import CameraError, FrameError, SourceError
from rangebearing.sources import (
    Frame,
    FrameSource,
    OpenCVSource,
    Picamera2Source,
    RecordedSource,
    open_source,
    validate_frame,
)

from .conftest import solid_bgr


class TestValidateFrame:
    def test_bgr_passes_through_unchanged(self) -> None:
        image = np.arange(4 * 5 * 3, dtype=np.uint8).reshape(4, 5, 3)
        out = validate_frame(image)
        assert out.shape == (4, 5, 3)
        np.testing.assert_array_equal(out, image)
        assert out.flags["C_CONTIGUOUS"]

    @pytest.mark.parametrize("shape", [(4, 5), (4, 5, 1)])
    def test_grey_becomes_three_equal_channels(self, shape: tuple) -> None:
        grey = np.arange(20, dtype=np.uint8).reshape(shape)
        out = validate_frame(grey)
        assert out.shape == (4, 5, 3)
        for c in range(3):
            np.testing.assert_array_equal(out[:, :, c], grey.reshape(4, 5))

    def test_four_channels_drop_the_fourth_and_keep_bgr_order(self) -> None:
        bgra = np.zeros((2, 3, 4), dtype=np.uint8)
        bgra[..., 0], bgra[..., 1], bgra[..., 2], bgra[..., 3] = 10, 20, 30, 255
        out = validate_frame(bgra)
        assert out.shape == (2, 3, 3)
        assert out[0, 0].tolist() == [10, 20, 30]
        assert out.flags["C_CONTIGUOUS"]

    def test_non_contiguous_input_is_made_contiguous(self) -> None:
        wide = np.zeros((4, 10, 3), dtype=np.uint8)
        out = validate_frame(wide[:, ::2])
        assert out.flags["C_CONTIGUOUS"] and out.shape == (4, 5, 3)

    @pytest.mark.parametrize(
        "bad, words",
        [
            (None, "no image"),
            ([[1, 2], [3, 4]], "numpy"),
            (np.zeros((0, 5, 3), np.uint8), "empty"),
            (np.zeros((4, 5, 3), np.float32), "uint8"),
            (np.zeros((4, 5, 3), np.uint16), "uint8"),
            (np.zeros((4, 5, 2), np.uint8), "shape"),
            (np.zeros((4, 5, 3, 1), np.uint8), "shape"),
            (np.zeros(5, np.uint8), "shape"),
        ],
    )
    def test_bad_images_raise_frame_error(self, bad: object, words: str) -> None:
        with pytest.raises(FrameError, match=words):
            validate_frame(bad)

    def test_frame_error_is_also_a_value_error(self) -> None:
        with pytest.raises(ValueError):
            validate_frame(None)


def test_frame_is_frozen() -> None:
    frame = Frame(solid_bgr(1), 5, 0, "0")
    with pytest.raises(dataclasses.FrozenInstanceError):
        frame.index = 3  # type: ignore[misc]


def test_every_source_satisfies_the_protocol(tmp_path: Path) -> None:
    sources = [
        RecordedSource(tmp_path),
        OpenCVSource("0"),
        Picamera2Source(SourceConfig()),
    ]
    for source in sources:
        assert isinstance(source, FrameSource)
        assert source.dropped == 0
    assert not isinstance(object(), FrameSource)


def _write_dir(tmp_path: Path, n: int = 3) -> Path:
    for i in range(n):
        cv2.imwrite(str(tmp_path / f"f{i:03d}.png"), solid_bgr(10 * i))
    return tmp_path


class TestOpenSource:
    def test_recorded_is_opened_and_reads(self, tmp_path: Path) -> None:
        cfg = SourceConfig(kind="recorded", path=str(_write_dir(tmp_path)), fps=0.0)
        source = open_source(cfg, CameraIntrinsics())
        try:
            assert isinstance(source, RecordedSource)
            source.open()  # a second open is harmless
            frames = [source.read() for _ in range(4)]
        finally:
            source.close()
        assert [f.name for f in frames[:3] if f] == ["f000.png", "f001.png", "f002.png"]
        assert frames[3] is None

    def test_recorded_missing_path_raises_at_open(self, tmp_path: Path) -> None:
        cfg = SourceConfig(kind="recorded", path=str(tmp_path / "nope"))
        with pytest.raises(SourceError, match="no such file"):
            open_source(cfg, CameraIntrinsics())

    def test_opencv_kind_opens_a_video(self, tiny_video: Path) -> None:
        cfg = SourceConfig(kind="opencv", device=str(tiny_video))
        source = open_source(cfg, CameraIntrinsics())
        try:
            assert isinstance(source, OpenCVSource)
            first = source.read()
        finally:
            source.close()
        assert first is not None and first.index == 0

    def test_picamera2_kind_uses_the_camera(self, fake_picamera2: ModuleType) -> None:
        cfg = SourceConfig(kind="picamera2", width_px=32, height_px=24, timeout_s=0.5)
        source = open_source(cfg, CameraIntrinsics())
        try:
            assert isinstance(source, Picamera2Source)
            frame = source.read()
        finally:
            source.close()
        assert frame is not None and frame.image.shape == (24, 32, 3)
        assert fake_picamera2.WORLD.open_cameras == set()

    def test_picamera2_missing_camera_is_a_camera_error(self, fake_picamera2: ModuleType) -> None:
        fake_picamera2.WORLD.num_cameras = 0
        cfg = SourceConfig(kind="picamera2", retries=0)
        with pytest.raises(CameraError, match="no camera 0"):
            open_source(cfg, CameraIntrinsics())

    def test_unknown_kind(self) -> None:
        with pytest.raises(SourceError, match="unknown source kind"):
            open_source(SourceConfig(kind="tape"), CameraIntrinsics())


def test_open_source_paces_with_the_given_sleep(tmp_path: Path) -> None:
    slept: List[float] = []

    def sleep(s: float) -> None:  # slept for real: the pacer waits on the real clock
        slept.append(s)
        time.sleep(s)

    # 100 ms a frame, 25 frames: a decode that overruns on a loaded machine drops frames, never runs out
    # (3 frames at 50 fps did: the pacer dropped to the last frame and the third read found none)
    cfg = SourceConfig(kind="recorded", path=str(_write_dir(tmp_path, 25)), fps=10.0)
    source = open_source(cfg, CameraIntrinsics(), sleep=sleep)
    try:
        for _ in range(3):
            assert source.read() is not None
    finally:
        source.close()
    assert slept and all(0 < s <= 0.1 + 1e-9 for s in slept)
