"""The hub: nothing drawn or encoded without a viewer, a capped rate with one, thresholds handed over once."""

from __future__ import annotations

import dataclasses
import json
import threading
import time

import cv2
import numpy as np
import pytest

from rangebearing.config import Config
from rangebearing.core.pipeline import Pipeline
from rangebearing.core.types import FrameResult
from rangebearing.view import Thresholds, ViewHub
from rangebearing.view import hub as hub_mod

CFG = Config()


@pytest.fixture
def frame(static_clip) -> np.ndarray:
    return cv2.imread(str(sorted(static_clip.iterdir())[0]))


def make_hub(**kw) -> ViewHub:
    hub = ViewHub(Thresholds.of(CFG.detection), **kw)
    hub.start()
    return hub


def test_no_viewer_no_work(frame: np.ndarray) -> None:
    hub = make_hub()
    try:
        result = Pipeline(CFG.pipeline).process(frame)
        offered = 0
        for _ in range(50):
            now = time.monotonic_ns()
            if hub.wants(now):
                hub.offer(now, frame, "f", result, CFG.detection, {})
                offered += 1
        assert offered == 0 and hub.encoded == 0 and hub.snapshot.seq == 0
    finally:
        hub.close()


@pytest.mark.parametrize(("camera_fps", "expected"), [(30.0, 30), (90.0, 30), (7.0, 21), (12.0, 30)])
def test_rate_is_capped(frame: np.ndarray, camera_fps: float, expected: int) -> None:
    hub = make_hub(max_fps=10.0)
    try:
        result = Pipeline(CFG.pipeline).process(frame)
        offered = 0
        t0 = time.monotonic_ns()
        with hub.viewer():
            for i in range(int(3 * camera_fps)):  # three seconds of camera frames, on the camera's clock
                now = t0 + round(i * 1e9 / camera_fps)
                if hub.wants(now):
                    hub.offer(now, frame, "f", result, CFG.detection, {"fps": camera_fps})
                    offered += 1
            snap = hub.wait(0, 10.0)
        assert offered == expected  # 10 fps, or every frame of a slower camera
        assert snap is not None and snap.jpeg[:2] == b"\xff\xd8" and snap.masks_jpeg == b""
        state = json.loads(snap.state)
        assert len(state["landmarks"]) == 2 and state["stats"] == {"fps": camera_fps}
        assert not hub.wants(time.monotonic_ns() + 10**10)  # the viewer left
    finally:
        hub.close()


def test_masks_only_for_mask_viewers(frame: np.ndarray) -> None:
    hub = make_hub(max_fps=0)
    try:
        result = Pipeline(CFG.pipeline).process(frame)
        with hub.viewer("masks"):
            hub.offer(time.monotonic_ns(), frame, "f", result, CFG.detection, {})
            snap = hub.wait(0, 10.0)
        assert snap is not None
        masks = cv2.imdecode(np.frombuffer(snap.masks_jpeg, np.uint8), cv2.IMREAD_COLOR)
        assert masks.shape == (240, 320, 3)  # the detector's resolution (downscale 2)
        red = (masks[:, :, 2] > 200) & (masks[:, :, 0] < 90)
        assert red.sum() > 50  # both red bands show
    finally:
        hub.close()


def test_thresholds_are_handed_over_once() -> None:
    hub = ViewHub(Thresholds.of(CFG.detection))
    assert hub.take_thresholds() is None
    new = Thresholds(((0, 5),), ((100, 120),), 200, 30)
    hub.set_thresholds(new)
    assert hub.thresholds == new
    assert hub.take_thresholds() == new
    assert hub.take_thresholds() is None


def test_a_drawing_bug_does_not_stop_the_encoder(frame: np.ndarray, monkeypatch: pytest.MonkeyPatch) -> None:
    hub = make_hub(max_fps=0)
    try:
        result = Pipeline(CFG.pipeline).process(frame)
        real = hub_mod.draw.overlay
        calls = []
        failed = threading.Event()

        def flaky(*a, **k):
            calls.append(1)
            if len(calls) == 1:
                failed.set()
                raise ValueError("boom")
            return real(*a, **k)

        monkeypatch.setattr(hub_mod.draw, "overlay", flaky)
        with hub.viewer():
            hub.offer(time.monotonic_ns(), frame, "a", result, CFG.detection, {})
            assert failed.wait(10.0)  # "a" was drawn (and failed) before "b" is offered
            hub.offer(time.monotonic_ns(), frame, "b", result, CFG.detection, {})
            snap = hub.wait(0, 10.0)
        assert snap is not None and json.loads(snap.state)["frame"]["name"] == "b"
    finally:
        hub.close()


def test_numpy_numbers_in_a_reading_make_valid_json(frame: np.ndarray) -> None:
    hub = make_hub(max_fps=0)
    try:
        lm = Pipeline(CFG.pipeline).process(frame).landmarks[0]
        odd = dataclasses.replace(lm, bbox_px=tuple(np.int64(v) for v in lm.bbox_px), range_m=np.float32(lm.range_m))
        with hub.viewer():
            hub.offer(time.monotonic_ns(), frame, "f", FrameResult((odd,)), CFG.detection, {"n": np.int64(3)})
            snap = hub.wait(0, 10.0)
        assert snap is not None
        state = json.loads(snap.state)
        assert state["landmarks"][0]["bbox_px"] == [int(v) for v in lm.bbox_px] and state["stats"] == {"n": 3}
    finally:
        hub.close()
