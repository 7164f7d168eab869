"""The daemon's recorder never holds the loop or its stop: a writer stuck in a write, a writer that fails oddly."""

from __future__ import annotations

import logging
import threading
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rangebearing.core.types import CameraIntrinsics
from rangebearing.recording import McapRecording
from rangebearing.recording.background import BackgroundRecorder
from rangebearing.recording.mcap_writer import McapRecorder

pytest.importorskip("mcap")

CAMERA = CameraIntrinsics(width_px=64, height_px=48, fx_px=63.4, fy_px=63.0, cx_px=31.5, cy_px=23.5)
IMAGE = np.zeros((48, 64, 3), np.uint8)


def test_close_returns_when_the_writer_is_stuck_in_a_write(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                           caplog: pytest.LogCaptureFixture) -> None:
    entered, release = threading.Event(), threading.Event()

    def stuck(self: Any, *args: Any, **kwargs: Any) -> None:  # a USB stick pulled mid-write: the call never returns
        entered.set()
        release.wait(120)

    monkeypatch.setattr(McapRecorder, "write_encoded_image", stuck)
    rec = BackgroundRecorder(tmp_path / "run.mcap", CAMERA, image_format="png", queue_items=4)
    try:
        rec.add_frame(IMAGE, 1, 0)
        assert entered.wait(60)
        for i in range(10):  # the queue fills: the rest are dropped, counted, never waited for
            rec.add_frame(IMAGE, 2 + i, 1 + i)
        assert rec.counts["dropped"] >= 6
        rec.close(timeout_s=0.5)  # would block forever putting its stop item into the full queue
        rec.close(timeout_s=0.5)  # and a second close does not wait again
        stuck_lines = [r for r in caplog.records if "not finished" in r.getMessage()]
        assert len(stuck_lines) == 1 and stuck_lines[0].levelno == logging.WARNING
    finally:
        release.set()


def test_an_unexpected_writer_error_stops_the_recording_not_the_caller(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken(self: Any, *args: Any, **kwargs: Any) -> None:
        raise struct_error("unpack requires a buffer of 8 bytes")

    monkeypatch.setattr(McapRecorder, "write_reading", broken)
    rec = BackgroundRecorder(tmp_path / "run.mcap", CAMERA, image_format="png", queue_items=4)
    rec.add_frame(IMAGE, 1, 0)
    rec.add_reading(b"{}", 1)
    for i in range(20):  # the thread is gone or failed: never blocks, never raises
        rec.add(IMAGE, 2 + i, b"{}", 1.0 + i)
    rec.close(timeout_s=60)
    assert rec.failed is not None and "unpack" in rec.failed and rec.counts["errors"] == 1
    assert [f.index for f in McapRecording(tmp_path / "run.mcap").frames()] == [0]  # what came before is kept


def struct_error(msg: str) -> Exception:
    import struct

    return struct.error(msg)
