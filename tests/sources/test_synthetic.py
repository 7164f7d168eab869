"""SyntheticSource: rendered frames of a landmark on a known path, paced like a camera."""

from __future__ import annotations

import math
from typing import List

import numpy as np
import pytest

from rangebearing.config import SourceConfig
from rangebearing.core.types import CameraIntrinsics
from rangebearing.errors import SourceError
from rangebearing.sources import FrameSource, open_source
from rangebearing.sources.synthetic import SyntheticSource, figure_eight
from rangebearing.synth.scene import LandmarkPose

FPS = 10.0
PERIOD_NS = 100_000_000


class FakeClock:
    def __init__(self) -> None:
        self.t_ns = 5_000_000_000
        self.sleeps: List[float] = []

    def __call__(self) -> int:
        return self.t_ns

    def sleep(self, seconds: float) -> None:
        self.sleeps.append(seconds)
        self.t_ns += round(seconds * 1e9)


def small_cfg() -> SourceConfig:
    return SourceConfig(kind="synthetic", fps=FPS, width_px=160, height_px=120)


def red_centroid_x(bgr: np.ndarray) -> float:
    b, g, r = (bgr[..., c].astype(int) for c in range(3))
    _ys, xs = np.nonzero((r > 100) & (r > 2 * g) & (r > 2 * b))
    assert xs.size > 0, "no red band in the frame"
    return float(xs.mean())


def test_frames_show_the_landmark_where_the_truth_says() -> None:
    clock = FakeClock()
    source = SyntheticSource(small_cfg(), CameraIntrinsics(), frames=3,
                             clock=clock, sleep=clock.sleep)
    assert isinstance(source, FrameSource)
    source.open()
    frames = [source.read() for _ in range(3)]
    assert source.read() is None
    source.close()
    cam = CameraIntrinsics().scaled(160, 120)
    for frame in frames:
        assert frame is not None and frame.image.shape == (120, 160, 3)
        (pose,) = source.truth(frame.index)
        expected_x = cam.cx_px - cam.fx_px * math.tan(pose.bearing_rad)
        assert red_centroid_x(frame.image) == pytest.approx(expected_x, abs=1.5)
    assert [f.index for f in frames if f] == [0, 1, 2]
    assert [f.t_mono_ns for f in frames if f] == [5_000_000_000 + i * PERIOD_NS for i in range(3)]


def test_slow_consumer_drops_frames() -> None:
    clock = FakeClock()
    path_calls: List[float] = []

    def still(t_s: float) -> tuple:
        path_calls.append(t_s)
        return (LandmarkPose(0.6, 0.0),)

    source = SyntheticSource(small_cfg(), CameraIntrinsics(), path=still,
                             clock=clock, sleep=clock.sleep)
    source.open()
    source.read()
    clock.t_ns += 5 * PERIOD_NS
    frame = source.read()
    assert frame is not None and frame.index == 5 and source.dropped == 4
    assert path_calls == [0.0, 0.5]  # only the delivered frames are rendered


def test_default_path_stays_in_the_working_envelope() -> None:
    for t in np.linspace(0.0, 70.0, 141):
        (pose,) = figure_eight(float(t))
        assert 0.3 - 1e-9 <= pose.range_m <= 1.2 + 1e-9
        assert abs(pose.bearing_rad) <= 0.35 + 1e-9


def test_read_before_open() -> None:
    with pytest.raises(SourceError, match="not open"):
        SyntheticSource(small_cfg(), CameraIntrinsics()).read()


def test_open_source_builds_it() -> None:
    source = open_source(small_cfg(), CameraIntrinsics())
    try:
        assert isinstance(source, SyntheticSource)
        frame = source.read()
    finally:
        source.close()
    assert frame is not None and frame.index == 0 and frame.image.shape == (120, 160, 3)


def test_zero_fps_renders_as_fast_as_asked() -> None:
    clock = FakeClock()
    cfg = SourceConfig(kind="synthetic", fps=0.0, width_px=160, height_px=120)
    source = SyntheticSource(cfg, CameraIntrinsics(), frames=2, clock=clock, sleep=clock.sleep)
    source.open()
    frames = [source.read(), source.read(), source.read()]
    assert [f.index for f in frames if f] == [0, 1] and frames[2] is None
    assert clock.sleeps == [] and source.dropped == 0
