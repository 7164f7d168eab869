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


def test_a_false_wait_gives_a_job_with_get_result(fake_picamera2: ModuleType) -> None:
    cam = started(fake_picamera2)
    job = cam.capture_request(wait=0)  # dispatch_functions: `if wait` is false, so the Job itself
    request = job.get_result(timeout=0.5)  # job.py's Job.get_result, as Picamera2.wait(job) calls it
    assert request.make_array("main").shape == (6, 8, 3)
    request.release()
    assert cam.wait(cam.capture_request(wait=False), timeout=0.5).release() is None
    assert fake_picamera2.WORLD.outstanding == []
    cam.close()


def test_capture_array_and_metadata_release_their_request(fake_picamera2: ModuleType) -> None:
    fake_picamera2.WORLD.producer = red
    cam = started(fake_picamera2)
    array = cam.capture_array("main", wait=0.5)  # capture_array_: make_array, then release
    assert array.shape == (6, 8, 3) and array.flags.c_contiguous and array[0, 0].tolist() == [0, 0, 200]
    assert isinstance(cam.capture_metadata(wait=0.5)["SensorTimestamp"], int)
    assert fake_picamera2.WORLD.outstanding == []  # nothing held: the camera keeps running
    assert all(cam.capture_array(wait=0.5) is not None for _ in range(5))  # more than buffer_count frames
    cam.close()


def test_configure_checks_streams_as_picamera2_does(fake_picamera2: ModuleType) -> None:
    cam = fake_picamera2.Picamera2(0)
    config = cam.create_video_configuration(main={"format": "RGB888", "size": (8, 6)})
    for main, message in (({"format": "RGB888", "size": [8, 6]}, "should be \\(width, height\\)"),
                          ({"format": "RGB888", "size": (7, 6)}, "should be even"),
                          ({"size": (8, 6)}, "format not found")):
        with pytest.raises(RuntimeError, match=message):
            cam.configure({**config, "main": main})
    with pytest.raises(RuntimeError, match="'raw' key expected"):
        cam.configure({k: v for k, v in config.items() if k != "raw"})
    cam.close()


def test_configure_fills_in_the_callers_stream_dicts(fake_picamera2: ModuleType) -> None:
    cam = fake_picamera2.Picamera2(0)
    config = cam.create_video_configuration(main={"format": "RGB888", "size": (100, 10)},
                                            lores={"format": "YUV420", "size": (100, 10)})
    cam.configure(config)  # picamera2 copies the outer dict only; _update_stream_config writes into the streams
    assert config["main"]["stride"] == cam.stream_configuration("main")["stride"] == 320
    lores = cam.stream_configuration("lores")
    assert lores["stride"] == 128 > lores["size"][0] and config["lores"] is lores
    with pytest.raises(KeyError):
        cam.stream_configuration("nope")
    cam.close()


def test_padded_lores_keeps_u_and_v_at_half_the_stride(fake_picamera2: ModuleType) -> None:
    fake_picamera2.WORLD.producer = red
    cam = fake_picamera2.Picamera2(0)
    cam.configure(cam.create_video_configuration(main={"format": "RGB888", "size": (100, 10)},
                                                 lores={"format": "YUV420", "size": (100, 10)}))
    cam.start()
    request = cam.capture_request(wait=0.5)
    with fake_picamera2.MappedArray(request, "lores") as m:
        buf = m.array
        assert buf.shape == (15, 128)
        chroma = buf[10:].reshape(2, 5, 64)  # U then V: 5 rows each of stride/2 bytes
        u, v = chroma[0, :, :50], chroma[1, :, :50]
        assert int(v.mean()) > 200 > 100 > int(u.mean())  # red: Cr high, Cb low
        assert (chroma[:, :, 50:] == 77).all()  # the padding is junk, not pixels
    request.release()
    cam.close()


def test_align_configuration_rounds_to_the_isp(fake_picamera2: ModuleType) -> None:
    cam = fake_picamera2.Picamera2(0)
    config = cam.create_video_configuration(main={"format": "RGB888", "size": (101, 11)},
                                            lores={"format": "YUV420", "size": (100, 10)})
    assert config["main"]["size"] == (100, 10)  # align_stream(optimal=False): even
    cam.align_configuration(config)
    assert config["main"]["size"] == (96, 10) and config["lores"]["size"] == (64, 10)
    cam.close()
