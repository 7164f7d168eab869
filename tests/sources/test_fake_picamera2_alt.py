"""The clean-room fake (tests/fakes/picamera2_alt) behaves as the real picamera2 source says (3e6dff0).

These pin the fake itself, so that what the source tests lean on is the real library's behaviour.
"""

from __future__ import annotations

import os
import stat
import threading
from concurrent.futures import TimeoutError as FutureTimeout
from typing import Any, Iterator

import numpy as np
import pytest


@pytest.fixture
def cam(alt_picamera2: Any) -> Iterator[Any]:
    module, _ = alt_picamera2
    camera = module.Picamera2(0)
    yield camera
    camera.close()


def video(cam: Any, **kw: Any) -> dict:
    return cam.create_video_configuration(**{"main": {"size": (40, 30), "format": "RGB888"}, **kw})


@pytest.mark.parametrize("fmt, order", [("RGB888", [2, 1, 0]), ("BGR888", [0, 1, 2]), ("XBGR8888", [0, 1, 2]),
                                        ("XRGB8888", [2, 1, 0])])
def test_byte_orders_follow_the_pil_modes(alt_picamera2: Any, cam: Any, fmt: str, order: list) -> None:
    _, rig = alt_picamera2
    rgb = np.zeros((30, 40, 3), np.uint8)
    rgb[..., 0], rgb[..., 1], rgb[..., 2] = 10, 20, 30
    rig.RIG.scene = [rgb]
    cam.configure(video(cam, main={"size": (40, 30), "format": fmt}))
    cam.start()
    array = cam.capture_array("main", wait=10)
    assert array.shape == (30, 40, 3 if fmt.endswith("888") and len(fmt) == 6 else 4)
    assert array[0, 0, :3].tolist() == [[10, 20, 30][i] for i in order]  # request.py's PIL modes
    if array.shape[2] == 4:
        assert (array[..., 3] == 255).all()


def test_rows_are_padded_and_yuv420_keeps_its_stride(alt_picamera2: Any, cam: Any) -> None:
    module, _ = alt_picamera2
    cam.configure(video(cam, lores={"size": (40, 30)}))
    main, lores = cam.stream_configuration("main"), cam.stream_configuration("lores")
    assert (main["stride"], lores["stride"]) == (128, 64)  # VC4: 32-byte rows; Y 64 so U/V rows are 32
    assert lores["framesize"] == 64 * 30 * 3 // 2
    cam.start()
    request = cam.capture_request(wait=10)
    try:
        assert request.make_array("main").shape == (30, 40, 3) and request.make_array("main").flags.c_contiguous
        assert request.make_array("lores").shape == (45, 64)  # (H * 3 / 2, stride), padding left in
        with module.MappedArray(request, "main") as m:
            assert m.array.shape == (30, 40, 3) and not m.array.flags.c_contiguous  # a view, padding sliced off
    finally:
        request.release()


def test_capture_without_wait_blocks_and_with_wait_times_out_leaving_the_job(alt_picamera2: Any, cam: Any) -> None:
    _, rig = alt_picamera2
    cam.configure(video(cam))
    got: list = []
    waiter = threading.Thread(target=lambda: got.append(cam.capture_request()), daemon=True)
    waiter.start()  # not started: no frame will come
    waiter.join(0.3)
    assert waiter.is_alive()
    cam.start()
    waiter.join(30)
    assert not waiter.is_alive() and len(got) == 1  # the queued job took the first frame
    got[0].release()
    rig.RIG.stop_after = rig.RIG.frames_delivered
    assert rig.RIG.wait_ticks(3)
    with cam.lock:
        while cam.completed_requests:
            cam.completed_requests.pop(0).release()
    with pytest.raises(FutureTimeout):
        cam.capture_request(wait=0.05)
    assert len(cam._job_list) == 1  # still queued (dispatch_functions never unschedules it)
    rig.RIG.stop_after = None
    assert rig.RIG.wait_ticks(3)
    assert cam._job_list == [] and rig.held() == 1  # it ate a frame whose request nobody will release
    job = cam.capture_request(wait=False)  # a false wait returns the Job
    request = job.get_result(timeout=30)
    request.release()
    with pytest.raises(RuntimeError, match="negative ref_count"):
        request.release()
    with pytest.raises(RuntimeError, match="not defined"):
        request.make_array("main")


def test_configurations_the_real_one_refuses(alt_picamera2: Any, cam: Any) -> None:
    _, rig = alt_picamera2
    listed = video(cam, main={"size": [40, 30], "format": "RGB888"})
    assert listed["main"]["size"] == (40, 30)  # create_* aligns it into a tuple (align_stream) ...
    listed["main"]["size"] = [40, 30]
    with pytest.raises(RuntimeError, match=r"should be \(width, height\)"):  # ... configure() refuses a list
        cam.configure(listed)
    odd = video(cam, main={"size": (41, 30), "format": "RGB888"})
    assert odd["main"]["size"] == (40, 30)  # made even by create_* ...
    odd["main"]["size"] = (41, 30)
    with pytest.raises(RuntimeError, match="even"):  # ... refused by configure()
        cam.configure(odd)
    with pytest.raises(RuntimeError, match="may not exceed"):
        cam.configure(video(cam, lores={"size": (64, 30)}))
    with pytest.raises(RuntimeError, match="lores stream must be YUV"):  # Pi 4
        cam.configure(video(cam, lores={"size": (40, 30), "format": "BGR888"}))
    with pytest.raises(ValueError, match="Bad key"):
        video(cam, lores={"size": (40, 30), "colour": 1})
    with pytest.raises(RuntimeError, match="not advertised"):
        cam.configure(video(cam, controls={"NoSuchControl": 1}))
    rig.RIG.platform = "pisp"  # Pi 5: lores may be RGB
    cam.configure(video(cam, lores={"size": (40, 30), "format": "BGR888"}))
    assert cam.camera_configuration()["lores"]["format"] == "BGR888"


def test_sensor_modes_reconfigure_the_camera(cam: Any) -> None:
    cam.configure(video(cam, lores={"size": (40, 30)}))
    assert cam.camera_configuration()["lores"] is not None
    modes = cam.sensor_modes
    assert len(modes) == 3 and modes[0]["size"] == (1536, 864)
    assert cam.camera_configuration()["lores"] is None  # the last mode's preview configuration now


def test_missing_and_busy_cameras_fail_as_the_real_constructor(alt_picamera2: Any, cam: Any) -> None:
    module, _ = alt_picamera2
    with pytest.raises(RuntimeError, match="did not complete") as busy:
        module.Picamera2(0)
    assert "busy" in str(busy.value.__cause__)
    before = _pipes()
    with pytest.raises(IndexError):
        module.Picamera2(1)
    assert len(_pipes() - before) == 2  # the notify pipe's two ends, opened before the lookup (349-355)


def _pipes() -> set:
    """(descriptor, inode) of every pipe this process holds."""
    held = set()
    for name in os.listdir("/proc/self/fd"):
        try:
            info = os.fstat(int(name))
        except OSError:  # closed meanwhile (the listing's own descriptor)
            continue
        if stat.S_ISFIFO(info.st_mode):
            held.add((int(name), info.st_ino))
    return held
