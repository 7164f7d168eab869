"""Picamera2Source reads what libcamera granted (formats, colour space, strides), not what it asked for."""

from __future__ import annotations

import logging
from types import ModuleType
from typing import Any

import numpy as np
import pytest

from rangebearing.core.yuv import yuv420_from_bgr
from rangebearing.errors import CameraError
from rangebearing.sources import Picamera2Source
from tests.sources.test_picamera2_source import H, Sleeps, W, make_cfg, red


def _first_frame(world: Any, **cfg: Any) -> Any:
    source = Picamera2Source(make_cfg(**cfg), sleep=Sleeps(), in_place=True)
    source.open()
    try:
        frame = source.read()
        assert frame is not None
        yuv = frame.lores_yuv420
        return frame.image.copy(), yuv and (yuv.y.copy(), yuv.u.copy(), yuv.v.copy(), yuv.colour_space)
    finally:
        source.close()


@pytest.mark.parametrize("fmt", ["RGB888", "BGR888", "XBGR8888", "XRGB8888"])
def test_every_rgb_layout_the_camera_may_grant_reads_as_bgr(fake_picamera2: ModuleType, fmt: str) -> None:
    world = fake_picamera2.WORLD
    world.producer = red
    world.adjusted = {"main": {"format": fmt}}
    image, _ = _first_frame(world)  # W = 40: rows of 40 × 3 or 4 bytes, padded to 64-byte strides
    assert image.shape == (H, W, 3) and image.flags.c_contiguous
    assert (image[..., 2] == 255).all() and (image[..., :2] == 0).all()  # red, and no padding (77) read


@pytest.mark.parametrize("fmt", ["SRGGB10_CSI2P", "R8", "P010"])  # raw Bayer, mono, a format picamera2 lacks
def test_a_main_stream_in_no_colour_format_is_a_clear_error_and_frees_the_camera(fake_picamera2: ModuleType,
                                                                                 fmt: str) -> None:
    world = fake_picamera2.WORLD
    world.adjusted = {"main": {"format": fmt}}
    fake_picamera2._BYTES_PER_PIXEL[fmt] = 2  # the fake knows the format only for this test
    try:
        with pytest.raises(CameraError, match=rf"main stream as '{fmt}'.*source\.kind: opencv"):
            Picamera2Source(make_cfg(retries=1), sleep=Sleeps()).open()
    finally:
        del fake_picamera2._BYTES_PER_PIXEL[fmt]
    assert world.open_cameras == set()  # closed again: the next attempt can have it


def test_yvu420_lores_has_its_chroma_planes_swapped_back(fake_picamera2: ModuleType) -> None:
    world = fake_picamera2.WORLD
    world.producer = lambda seq, h, w: np.random.default_rng(seq).integers(0, 256, (h, w, 3), np.uint8)
    world.adjusted = {"lores": {"format": "YVU420"}}
    image, (y, u, v, space) = _first_frame(world)
    want = yuv420_from_bgr(image)
    assert np.array_equal(y, want.y) and np.array_equal(u, want.u) and np.array_equal(v, want.v)
    assert space == "smpte170m"


def test_lores_is_read_with_the_matrix_of_the_colour_space_granted(fake_picamera2: ModuleType) -> None:
    import libcamera

    fake_picamera2.WORLD.adjusted = {"colour_space": libcamera.ColorSpace.Rec709()}
    _, lores = _first_frame(fake_picamera2.WORLD)
    assert lores[3] == "rec709"


def test_a_colour_space_the_search_cannot_read_leaves_the_main_image_to_search(
        fake_picamera2: ModuleType, caplog: pytest.LogCaptureFixture) -> None:
    import libcamera

    odd = libcamera.ColorSpace.Rec709()
    odd.ycbcrEncoding = libcamera.ColorSpace.YcbcrEncoding.Rec2020
    fake_picamera2.WORLD.adjusted = {"colour_space": odd}
    with caplog.at_level(logging.WARNING):
        image, lores = _first_frame(fake_picamera2.WORLD)
    assert lores is None and image.shape == (H, W, 3)
    assert "searching the main image instead" in caplog.text


def test_no_camera_is_found_without_constructing_picamera2(fake_picamera2: ModuleType) -> None:
    world = fake_picamera2.WORLD
    world.num_cameras = 0
    with pytest.raises(CameraError, match=r"no camera 0 \(0 found\)"):
        Picamera2Source(make_cfg(retries=2), sleep=Sleeps()).open()
    assert world.instances == []  # picamera2's constructor would have opened a pipe and leaked it
