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


def grey(seq: int, h: int, w: int) -> np.ndarray:
    return np.full((h, w, 3), 100, np.uint8)


def test_controls_lock_exposure_and_white_balance_a_few_frames_later(fake_picamera2: ModuleType) -> None:
    world = fake_picamera2.WORLD
    world.producer = grey
    world.auto_drift = lambda seq: 1.0 + 0.1 * seq  # AE chases what fills the frame
    cam = started(fake_picamera2)

    def grab() -> Any:
        request = cam.capture_request(wait=0.5)
        try:
            return request.make_array("main")[0, 0].tolist(), request.get_metadata()
        finally:
            request.release()

    pixel, md = grab()
    assert pixel == [100, 100, 100]  # auto: the producer's frame as is
    assert set(md) >= {"ExposureTime", "AnalogueGain", "ColourGains", "DigitalGain", "ScalerCrop", "Lux"}
    assert md["ScalerCrop"] == (0, 2, 3280, 2460)  # the centred 4:3 window of the 3280×2464 array
    locked = {"AeEnable": False, "ExposureTime": md["ExposureTime"], "AnalogueGain": md["AnalogueGain"],
              "AwbEnable": False, "ColourGains": (world.auto_colour_gains[0] * 1.2, world.auto_colour_gains[1])}
    cam.set_controls(locked)
    assert world.set_controls_calls == [locked]
    later = [grab() for _ in range(4)]
    assert later[0][1]["ExposureTime"] != md["ExposureTime"]  # latency: still auto
    pixel, md2 = later[-1]
    assert md2["ExposureTime"] == md["ExposureTime"] and md2["ColourGains"][0] == pytest.approx(1.9 * 1.2)
    # locked at frame 1's exposure (AE then wanted 1.1×) while AE would now pick 1.5×: 100·1.1/1.5 = 73,
    # and red ×1.2 on top ([B, G, R] order)
    assert pixel == [73, 73, 88]
    with pytest.raises(RuntimeError, match="not advertised"):
        cam.set_controls({"Bogus": 1})
    cam.close()


@pytest.mark.parametrize("wait, signal", [(False, None), (0, None), (0.0, None), (None, print)])
def test_a_false_wait_or_a_signal_function_returns_the_job_as_dispatch_functions_does(
        fake_picamera2: ModuleType, wait: Any, signal: Any) -> None:
    cam = started(fake_picamera2)
    job = cam.capture_request(wait=wait, signal_function=signal)
    assert not isinstance(job, fake_picamera2.CompletedRequest)
    job.future.result(timeout=1).release()
    cam.close()


def test_main_rows_are_padded_to_the_stride_and_mapped_without_it(fake_picamera2: ModuleType) -> None:
    fake_picamera2.WORLD.producer = red
    cam = started(fake_picamera2)  # 8 px × 3 bytes = 24: rows of 64 bytes
    main = cam.camera_configuration()["main"]
    assert main["stride"] == 64 and main["framesize"] == 64 * 6
    request = cam.capture_request(wait=0.5)
    with fake_picamera2.MappedArray(request, "main") as m:
        assert m.array.shape == (6, 8, 3) and not m.array.flags.c_contiguous  # a view that skips the padding
        assert (m.array == [0, 0, 200]).all()
    copy = request.make_array("main")
    assert copy.flags.c_contiguous and copy.shape == (6, 8, 3)
    request.release()
    cam.close()


def test_what_libcamera_grants_instead_is_what_the_configuration_says(fake_picamera2: ModuleType) -> None:
    import libcamera

    fake_picamera2.WORLD.adjusted = {"main": {"format": "XBGR8888"}, "lores": {"format": "YVU420"},
                                     "colour_space": libcamera.ColorSpace.Rec709()}
    cam = fake_picamera2.Picamera2(0)
    cam.configure(cam.create_video_configuration(main={"format": "RGB888", "size": (8, 6)}, lores={}))
    granted = cam.camera_configuration()
    assert granted["main"]["format"] == "XBGR8888" and granted["lores"]["format"] == "YVU420"
    assert granted["colour_space"] == libcamera.ColorSpace.Rec709()
    cam.close()
