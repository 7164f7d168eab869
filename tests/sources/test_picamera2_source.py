"""Picamera2Source against the faithful fake in tests/fakes/picamera2."""

from __future__ import annotations

import logging
import sys
import time
from types import ModuleType
from typing import Any, Iterator, List

import numpy as np
import pytest

from rangebearing.config import SourceConfig
from rangebearing.core.yuv import yuv420_from_bgr
from rangebearing.errors import CameraError, FrameError, SourceError
from rangebearing.sources import Picamera2Source
from rangebearing.sources.picamera2_source import (
    camera_controls,
    frames_missed,
    sensor_to_monotonic_ns,
)

W, H = 40, 30


def make_cfg(**kw: object) -> SourceConfig:
    base = {"width_px": W, "height_px": H, "fps": 30.0, "timeout_s": 0.02, "retries": 3}
    base.update(kw)
    return SourceConfig(**base)  # type: ignore[arg-type]


def red(seq: int, h: int, w: int) -> np.ndarray:
    rgb = np.zeros((h, w, 3), np.uint8)
    rgb[..., 0] = 255  # RGB content: pure red
    return rgb


class Sleeps:
    def __init__(self) -> None:
        self.calls: List[float] = []

    def __call__(self, seconds: float) -> None:
        self.calls.append(seconds)


@pytest.fixture
def world(fake_picamera2: ModuleType) -> Any:
    return fake_picamera2.WORLD


@pytest.fixture
def opened(world: Any) -> Iterator[Picamera2Source]:
    source = Picamera2Source(make_cfg(), sleep=Sleeps(), in_place=True)
    source.open()
    yield source
    source.close()


class TestPureHelpers:
    def test_controls_fix_the_frame_rate_and_pass_user_controls(self) -> None:
        cfg = make_cfg(fps=20.0, controls=(("AeEnable", False), ("ColourGains", (1.5, 2.0))))
        assert camera_controls(cfg) == {
            "FrameDurationLimits": (50000, 50000), "AeEnable": False, "ColourGains": (1.5, 2.0),
        }

    def test_user_frame_limits_or_rate_win(self) -> None:
        limits = camera_controls(make_cfg(controls=(("FrameDurationLimits", (100, 200)),)))
        assert limits == {"FrameDurationLimits": (100, 200)}
        assert camera_controls(make_cfg(controls=(("FrameRate", 15.0),))) == {"FrameRate": 15.0}

    @pytest.mark.parametrize(
        "sensor, received, offset, expected",
        [
            (900, 1000, 0, 900),  # monotonic, as on a Pi: used as is
            (900, 1000, 5000, 900),  # in the past: already monotonic
            (5900, 1000, 5000, 900),  # in the future: BOOTTIME, minus the suspend time
            (9000, 1000, 5000, 1000),  # nonsense: the receive time
        ],
    )
    def test_sensor_timestamp_to_monotonic(self, sensor: int, received: int, offset: int,
                                           expected: int) -> None:
        assert sensor_to_monotonic_ns(sensor, received, offset) == expected

    @pytest.mark.parametrize(
        "prev, now, missed",
        [(None, 500, 0), (0, 100, 0), (0, 140, 0), (0, 200, 1), (0, 310, 2),
         (0, 50, 0), (100, 0, 0)],
    )
    def test_frames_missed(self, prev: object, now: int, missed: int) -> None:
        assert frames_missed(prev, now, 100.0) == missed  # type: ignore[arg-type]


class TestFrames:
    def test_pure_red_scene_is_high_in_channel_2(self, world: Any, opened: Picamera2Source) -> None:
        world.producer = red
        frame = opened.read()
        assert frame is not None
        assert frame.image.shape == (H, W, 3) and frame.image.dtype == np.uint8
        assert (frame.image[..., 2] == 255).all()
        assert (frame.image[..., :2] == 0).all()

    def test_padded_rows_are_cropped(self, world: Any, opened: Picamera2Source) -> None:
        world.producer = red
        world.padded_width_px = 6
        frame = opened.read()
        assert frame is not None and frame.image.shape == (H, W, 3)
        assert not (frame.image == 77).any()  # the fake's padding bytes

    def test_configuration_reaches_the_camera(self, world: Any) -> None:
        def halves(seq: int, h: int, w: int) -> np.ndarray:
            rgb = np.zeros((h, w, 3), np.uint8)
            rgb[:, : w // 2, 0] = 255  # red left, blue right
            rgb[:, w // 2 :, 2] = 255
            return rgb

        world.producer = halves
        # twice the exposure AE picks: the frame saturates, as the pixel checks below want
        cfg = make_cfg(fps=20.0, hflip=True, buffer_count=3, controls=(("ExposureTime", 24000),))
        source = Picamera2Source(cfg)
        source.open()
        try:
            cam = world.instances[0]
            frame = source.read()
            assert frame is not None
            left, right = frame.image[0, 0].tolist(), frame.image[0, -1].tolist()  # valid until the next read
        finally:
            source.close()
        config = cam.camera_config
        assert config["main"]["format"] == "RGB888" and config["main"]["size"] == (W, H)
        assert config["buffer_count"] == 3
        assert config["controls"]["FrameDurationLimits"] == (50000, 50000)
        assert config["controls"]["ExposureTime"] == 24000
        assert config["transform"].hflip and not config["transform"].vflip
        assert left == [255, 0, 0]  # flipped: blue on the left (BGR)
        assert right == [0, 0, 255]

    def test_timestamps_follow_the_sensor(self, world: Any, opened: Picamera2Source) -> None:
        frames = [opened.read() for _ in range(4)]
        stamps = [f.t_mono_ns for f in frames if f]
        assert np.diff(stamps).tolist() == [33_333_000] * 3  # FrameDurationLimits at 30 fps
        assert stamps[-1] <= time.monotonic_ns()
        assert [f.index for f in frames if f] == [0, 1, 2, 3]
        assert [f.name for f in frames if f] == ["0", "1", "2", "3"]
        assert opened.dropped == 0

    def test_gaps_in_sensor_time_count_as_dropped(
        self, world: Any, opened: Picamera2Source
    ) -> None:
        opened.read()
        world.skip(2)
        frame = opened.read()
        assert frame is not None and frame.index == 3
        assert opened.dropped == 2
        after = opened.read()
        assert after is not None and after.index == 4

    def test_every_capture_passes_wait(self, world: Any, opened: Picamera2Source) -> None:
        opened.read()
        world.set_stalled(True)
        with pytest.raises(FrameError):
            opened.read()
        assert world.capture_waits == [0.02, 0.02]

    def test_every_request_is_released(self, world: Any, opened: Picamera2Source) -> None:
        for _ in range(10):  # more than buffer_count: a leak would stall the fake
            assert opened.read() is not None
            assert len(world.outstanding) == 1  # only the frame just returned is held
        opened.close()
        assert world.outstanding == []


class TestLores:
    def test_main_and_lores_are_configured_as_picamera2_wants(self, world: Any, opened: Picamera2Source,
                                                              fake_picamera2: ModuleType) -> None:
        config = world.instances[0].camera_config
        assert config["lores"]["format"] == "YUV420" and config["lores"]["size"] == (W, H)
        assert config["lores"]["stride"] == 64  # rows padded to the ISP's 64 bytes
        assert config["colour_space"].name == "SMPTE170M"  # the matrix the search's table assumes

    def test_lores_planes_are_the_frame_in_yuv420_read_in_place(self, world: Any) -> None:
        world.producer = lambda seq, h, w: np.random.default_rng(seq).integers(0, 256, (h, w, 3), np.uint8)
        opened = Picamera2Source(make_cfg(width_px=64, height_px=32), sleep=Sleeps(), in_place=True)
        opened.open()  # 64 × 3 bytes: main rows need no padding, so the frame is the camera's buffer itself
        frame = opened.read()
        assert frame is not None and frame.lores_yuv420 is not None
        yuv = frame.lores_yuv420
        want = yuv420_from_bgr(frame.image)
        assert yuv.y.shape == (32, 64) and yuv.u.shape == yuv.v.shape == (16, 32)
        assert np.array_equal(yuv.y, want.y)  # no stride padding (77) leaks in
        assert np.array_equal(yuv.u, want.u) and np.array_equal(yuv.v, want.v)
        before = frame.image.copy()
        opened.read()
        # the camera has the buffers back: views, not copies, and released at the next read
        assert (frame.image == 0xEE).all() and (yuv.u == 0xEE).all() and not (before == 0xEE).all()
        opened.close()

    def test_lores_off_means_main_only(self, world: Any) -> None:
        source = Picamera2Source(make_cfg(lores=False))
        source.open()
        try:
            frame = source.read()
            assert world.instances[0].camera_config["lores"] is None
            assert frame is not None and frame.lores_yuv420 is None
        finally:
            source.close()

    @pytest.mark.parametrize("old_picamera2", [False, True])
    def test_frames_to_keep_are_copies(self, world: Any, fake_picamera2: ModuleType,
                                       monkeypatch: pytest.MonkeyPatch, old_picamera2: bool) -> None:
        if old_picamera2:
            monkeypatch.delattr(fake_picamera2, "MappedArray")  # picamera2 before MappedArray: make_array
        source = Picamera2Source(make_cfg())  # not in place: the caller keeps frames (tune, record)
        source.open()
        try:
            first = source.read()
            assert world.outstanding == []  # released at once
            source.read()
        finally:
            source.close()
        assert first is not None and first.lores_yuv420 is not None
        assert not (first.image == 0xEE).any() and not (first.lores_yuv420.v == 0xEE).any()


class TestTimeouts:
    def test_a_timeout_is_survived(self, world: Any, opened: Picamera2Source) -> None:
        opened.read()
        world.set_stalled(True)
        with pytest.raises(FrameError, match="no frame within"):
            opened.read()
        cam = world.instances[0]
        assert cam._jobs == []  # flushed: the stale job cannot eat the next frame
        world.set_stalled(False)
        frame = opened.read()
        assert frame is not None and frame.index == 1
        assert len(world.outstanding) == 1  # the frame just returned; the timed-out job leaked none

    def test_consecutive_timeouts_become_a_camera_error(
        self, world: Any, opened: Picamera2Source
    ) -> None:
        world.set_stalled(True)
        for _ in range(2):
            with pytest.raises(FrameError) as info:
                opened.read()
            assert not isinstance(info.value, CameraError)
        with pytest.raises(CameraError, match="3 times in a row"):
            opened.read()

    def test_a_good_frame_resets_the_count(self, world: Any, opened: Picamera2Source) -> None:
        for _ in range(3):
            world.set_stalled(True)
            for _ in range(2):
                with pytest.raises(FrameError):
                    opened.read()
            world.set_stalled(False)
            assert opened.read() is not None


class TestOpening:
    def test_missing_camera_retries_with_backoff_then_fails(self, world: Any) -> None:
        world.num_cameras = 0
        sleeps = Sleeps()
        source = Picamera2Source(make_cfg(retries=3), sleep=sleeps, backoff_s=0.5)
        with pytest.raises(CameraError, match=r"no camera 0 \(0 found\)"):
            source.open()
        assert sleeps.calls == [0.5, 1.0, 2.0]

    def test_busy_camera_is_a_camera_error(self, world: Any, fake_picamera2: ModuleType) -> None:
        holder = fake_picamera2.Picamera2(0)
        source = Picamera2Source(make_cfg(retries=1), sleep=Sleeps())
        with pytest.raises(CameraError, match="busy"):
            source.open()
        holder.close()

    def test_busy_camera_freed_during_backoff_opens(
        self, world: Any, fake_picamera2: ModuleType
    ) -> None:
        holder = fake_picamera2.Picamera2(0)
        source = Picamera2Source(make_cfg(retries=2), sleep=lambda s: holder.close())
        source.open()
        try:
            assert source.read() is not None
        finally:
            source.close()

    def test_missing_library_gives_the_install_hint(self, monkeypatch: pytest.MonkeyPatch) -> None:
        monkeypatch.setitem(sys.modules, "picamera2", None)
        with pytest.raises(CameraError, match="--system-site-packages"):
            Picamera2Source(make_cfg()).open()

    def test_bad_control_fails_open_and_frees_the_camera(self, world: Any) -> None:
        source = Picamera2Source(make_cfg(controls=(("NoSuchControl", 1),)))
        with pytest.raises(CameraError, match="NoSuchControl"):
            source.open()
        assert world.open_cameras == set()

    def test_open_twice_is_harmless(self, world: Any, opened: Picamera2Source) -> None:
        opened.open()
        assert len(world.instances) == 1


class TestClosing:
    def test_close_releases_the_camera_and_is_idempotent(
        self, world: Any, fake_picamera2: ModuleType
    ) -> None:
        source = Picamera2Source(make_cfg())
        source.open()
        cam = world.instances[0]
        source.read()
        source.close()
        source.close()
        assert world.open_cameras == set() and world.outstanding == []
        assert not cam.is_open and cam.stop_calls >= 1
        with pytest.raises(SourceError, match="not open"):
            source.read()
        fake_picamera2.Picamera2(0).close()  # free again: nobody holds it

    def test_close_after_a_timeout_does_not_hang(self, world: Any) -> None:
        source = Picamera2Source(make_cfg(), stop_timeout_s=2.0)
        source.open()
        world.set_stalled(True)
        with pytest.raises(FrameError):
            source.read()
        t0 = time.monotonic()
        source.close()
        assert time.monotonic() - t0 < 1.0
        assert world.open_cameras == set()

    def test_a_hanging_stop_is_abandoned_and_logged(
        self, world: Any, caplog: pytest.LogCaptureFixture
    ) -> None:
        source = Picamera2Source(make_cfg(), stop_timeout_s=0.05)
        source.open()
        world.hang_stop = True
        t0 = time.monotonic()
        with caplog.at_level(logging.ERROR, logger="rangebearing.sources.picamera2_source"):
            source.close()
        assert time.monotonic() - t0 < 1.0
        assert "did not stop" in caplog.text


def test_no_frame_rate_control_without_a_rate() -> None:
    assert camera_controls(make_cfg(fps=0.0)) == {}


def test_a_sleep_that_returns_true_stops_the_retries(world: Any) -> None:
    world.num_cameras = 0
    calls: List[float] = []

    def interrupted(seconds: float) -> bool:
        calls.append(seconds)
        return True

    with pytest.raises(CameraError, match="no camera 0"):
        Picamera2Source(make_cfg(retries=5), sleep=interrupted).open()
    assert calls == [0.5]


def test_a_picamera2_without_capture_request_reads_capture_array(world: Any, fake_picamera2: ModuleType,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    class Arrays(fake_picamera2.Picamera2):  # type: ignore[name-defined,misc]
        capture_request = None  # only capture_array(name, wait=): copies, the request released inside

    monkeypatch.setattr(fake_picamera2, "Picamera2", Arrays)
    world.producer = red
    source = Picamera2Source(make_cfg(), sleep=Sleeps(), in_place=True)
    source.open()
    try:
        frames = [source.read() for _ in range(8)]  # more than buffer_count: nothing may be held
        assert all(f.image.shape == (H, W, 3) and f.image[0, 0].tolist() == [0, 0, 255] for f in frames)
        assert all(f.lores_yuv420 is None for f in frames)  # main only: searched in full
        assert world.outstanding == [] and set(world.capture_waits) == {0.02}
    finally:
        source.close()
