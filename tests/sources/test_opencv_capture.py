"""OpenCVSource: a real video file, and a scripted live capture for drops and timeouts."""

from __future__ import annotations

import logging
import queue
import threading
import time
from pathlib import Path
from typing import Any, Iterator, List, Optional, Tuple

import cv2
import numpy as np
import pytest

from rangebearing.errors import CameraError, FrameError, SourceError
from rangebearing.sources import OpenCVSource
from rangebearing.sources import opencv_capture as opencv_mod

from .conftest import frame_brightness, solid_bgr, video_levels

Item = Tuple[bool, Optional[np.ndarray]]


class ScriptedCapture:
    """Stands in for cv2.VideoCapture on a live camera: read() blocks until fed."""

    def __init__(self, target: Any) -> None:
        self.target = target
        self.items: queue.Queue[Item] = queue.Queue()
        self.props: List[Tuple[int, float]] = []
        self.released = threading.Event()
        self.reads_started = 0
        self.reads_returned = 0
        self.cond = threading.Condition()
        ScriptedCapture.last = self

    last: ScriptedCapture

    def isOpened(self) -> bool:
        return self.target != 99

    def set(self, prop: int, value: float) -> bool:
        self.props.append((prop, value))
        return True

    def read(self) -> Item:
        with self.cond:
            self.reads_started += 1
            self.cond.notify_all()
        item = self.items.get()
        with self.cond:
            self.reads_returned += 1
        return item

    def release(self) -> None:
        self.released.set()

    def feed(self, *images: np.ndarray) -> None:
        """Deliver frames and wait until the grabber has stored every one of them."""
        with self.cond:
            # Stored once the grabber has come back for the read after the last one.
            target = self.reads_returned + len(images) + 1
        for image in images:
            self.items.put((True, image))
        with self.cond:
            assert self.cond.wait_for(lambda: self.reads_started >= target, timeout=2.0)


@pytest.fixture
def live(monkeypatch: pytest.MonkeyPatch) -> Iterator[type]:
    monkeypatch.setattr(opencv_mod.cv2, "VideoCapture", ScriptedCapture)
    yield ScriptedCapture
    if hasattr(ScriptedCapture, "last"):
        ScriptedCapture.last.items.put((False, None))  # unblock a grabber left waiting
        del ScriptedCapture.last


class TestVideoFile:
    def test_every_frame_in_order_then_none(self, tiny_video: Path) -> None:
        source = OpenCVSource(str(tiny_video), timeout_s=2.0)
        source.open()
        try:
            frames = [source.read() for _ in range(6)]
            end = source.read()
        finally:
            source.close()
        assert end is None
        assert [f.index for f in frames if f] == list(range(6))
        assert [f.name for f in frames if f] == [str(i) for i in range(6)]
        levels = [frame_brightness(f.image) for f in frames if f]
        assert levels == pytest.approx(video_levels(), abs=4)
        assert source.dropped == 0
        stamps = [f.t_mono_ns for f in frames if f]
        assert stamps == sorted(stamps)

    def test_cannot_open(self, tmp_path: Path) -> None:
        bogus = tmp_path / "x.avi"
        bogus.write_text("nope")
        with pytest.raises(SourceError, match="cannot open"):
            OpenCVSource(str(bogus)).open()

    def test_read_before_open_and_double_close(self, tiny_video: Path) -> None:
        source = OpenCVSource(str(tiny_video))
        with pytest.raises(SourceError, match="not open"):
            source.read()
        source.open()
        source.close()
        source.close()


class TestLiveCapture:
    def test_index_device_and_requested_mode(self, live: type) -> None:
        source = OpenCVSource("2", 320, 240, 15.0, timeout_s=0.1)
        source.open()
        cap = live.last
        source.close()
        assert cap.target == 2
        assert (cv2.CAP_PROP_FRAME_WIDTH, 320) in cap.props
        assert (cv2.CAP_PROP_FPS, 15.0) in cap.props

    def test_device_that_will_not_open(self, live: type) -> None:
        with pytest.raises(SourceError, match="cannot open"):
            OpenCVSource("99").open()

    def test_only_the_newest_frame_is_kept(self, live: type) -> None:
        source = OpenCVSource("0", timeout_s=0.1)
        source.open()
        try:
            live.last.feed(solid_bgr(10), solid_bgr(20), solid_bgr(30))
            frame = source.read()
            assert frame is not None and frame.index == 2 and frame.name == "2"
            assert frame_brightness(frame.image) == 30
            assert source.dropped == 2
            live.last.feed(solid_bgr(40))
            nxt = source.read()
            assert nxt is not None and nxt.index == 3 and source.dropped == 2
        finally:
            source.close()

    def test_grey_frames_become_bgr_and_bad_ones_raise(self, live: type) -> None:
        source = OpenCVSource("0", timeout_s=0.1)
        source.open()
        try:
            live.last.feed(np.full((4, 5), 9, np.uint8))
            frame = source.read()
            assert frame is not None and frame.image.shape == (4, 5, 3)
            live.last.feed(np.zeros((4, 5, 3), np.float32))
            with pytest.raises(FrameError, match="uint8"):
                source.read()
            live.last.feed(solid_bgr(1))
            assert source.read() is not None
        finally:
            source.close()

    def test_timeouts_then_camera_error(self, live: type) -> None:
        source = OpenCVSource("0", timeout_s=0.02, retries=2)
        source.open()
        try:
            with pytest.raises(FrameError, match="no frame within") as first:
                source.read()
            assert not isinstance(first.value, CameraError)
            with pytest.raises(CameraError, match="2 times in a row"):
                source.read()
        finally:
            source.close()

    def test_stream_end_gives_none(self, live: type) -> None:
        source = OpenCVSource("0", timeout_s=1.0)
        source.open()
        try:
            live.last.items.put((False, None))
            assert source.read() is None
            assert live.last.released.wait(1.0)  # the grabber released the capture
        finally:
            source.close()

    def test_close_does_not_wait_forever_on_a_blocked_read(
        self, live: type, caplog: pytest.LogCaptureFixture
    ) -> None:
        source = OpenCVSource("0", timeout_s=0.05)
        source.open()
        t0 = time.monotonic()
        with caplog.at_level(logging.WARNING, logger="rangebearing.sources.opencv_capture"):
            source.close()
        assert time.monotonic() - t0 < 1.0
        assert "still blocked" in caplog.text
        assert not live.last.released.is_set()  # never released under a blocked read
        live.last.items.put((False, None))
        assert live.last.released.wait(1.0)  # the grabber releases it on its way out


def test_reopen_after_close_reads_from_the_start(tiny_video: Path) -> None:
    source = OpenCVSource(str(tiny_video), timeout_s=2.0)
    source.open()
    source.read()
    source.read()
    source.close()
    source.open()
    try:
        frame = source.read()
    finally:
        source.close()
    assert frame is not None and frame.index == 0
