"""The fake has to be faithful to be worth testing against: check its quirks."""

from __future__ import annotations

import concurrent.futures
from types import ModuleType
from typing import Any

import numpy as np
import pytest


def started(fake: ModuleType, fmt: str = "RGB888") -> Any:
    cam = fake.Picamera2(0)
    cam.configure(cam.create_video_configuration(main={"format": fmt, "size": (8, 6)},
                                                 buffer_count=2))
    cam.start()
    return cam


def red(seq: int, h: int, w: int) -> np.ndarray:
    rgb = np.zeros((h, w, 3), np.uint8)
    rgb[..., 0] = 200
    return rgb


@pytest.mark.parametrize(
    "fmt, pixel",
    [("RGB888", [0, 0, 200]), ("BGR888", [200, 0, 0]),
     ("XBGR8888", [200, 0, 0, 255]), ("XRGB8888", [0, 0, 200, 255])],
)
def test_byte_order_matches_the_manual(fake_picamera2: ModuleType, fmt: str, pixel: list) -> None:
    fake_picamera2.WORLD.producer = red
    cam = started(fake_picamera2, fmt)
    request = cam.capture_request(wait=0.5)
    try:
        assert request.make_array("main")[0, 0].tolist() == pixel
        assert "SensorTimestamp" in request.get_metadata()
    finally:
        request.release()
    cam.close()


def test_missing_and_busy(fake_picamera2: ModuleType) -> None:
    with pytest.raises(IndexError):
        fake_picamera2.Picamera2(1)
    cam = fake_picamera2.Picamera2(0)
    with pytest.raises(RuntimeError, match="did not complete"):
        fake_picamera2.Picamera2(0)
    cam.close()


def test_timed_out_job_stays_queued_and_eats_a_frame(fake_picamera2: ModuleType) -> None:
    world = fake_picamera2.WORLD
    cam = started(fake_picamera2)
    world.set_stalled(True)
    with pytest.raises(concurrent.futures.TimeoutError):
        cam.capture_request(wait=0.01)
    world.set_stalled(False)
    assert len(world.outstanding) == 1  # the stale job took a frame nobody will release
    world.outstanding[0].release()
    cam.close()


def test_flush_cancels_the_stale_job(fake_picamera2: ModuleType) -> None:
    world = fake_picamera2.WORLD
    cam = started(fake_picamera2)
    world.set_stalled(True)
    job = cam.capture_request(wait=False)
    cam.cancel_all_and_flush()
    with pytest.raises(concurrent.futures.CancelledError):
        job.future.result(timeout=0.5)
    world.set_stalled(False)
    assert world.outstanding == []
    cam.close()


def test_held_buffers_stall_the_camera(fake_picamera2: ModuleType) -> None:
    cam = started(fake_picamera2)  # buffer_count=2
    held = [cam.capture_request(wait=0.5) for _ in range(2)]
    with pytest.raises(concurrent.futures.TimeoutError):
        cam.capture_request(wait=0.01)
    held[0].release()  # frees a buffer: the queued job completes
    assert len(fake_picamera2.WORLD.outstanding) == 2
    with pytest.raises(RuntimeError, match="negative"):
        held[0].release()
    cam.cancel_all_and_flush()
    for request in list(fake_picamera2.WORLD.outstanding):
        request.release()
    cam.close()
