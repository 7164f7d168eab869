"""The periodic full scan in capture time (detection.full_scan_interval_s): as often per second at any rate."""

from __future__ import annotations

import dataclasses
import math

import pytest
from tests.core.test_tracking import moving_sequence

from rangebearing import Pipeline, load_config
from rangebearing.core.scans import Cadence, scan_due

NOMINAL = 1 / 30


def _scans(fps: float, seconds: float, every: int = 8, interval_s: float = 0.25, timed: bool = True):
    """Frames scanned whole when every other frame is tracked, as the pipeline steps its cadence."""
    c, out = Cadence(), []
    for i in range(round(fps * seconds)):
        t = i / fps if timed else None
        if i == 0 or scan_due(c, t, every, interval_s, NOMINAL):
            c = Cadence(0, t)
            out.append(i)
        else:
            c = Cadence(c.tracked + 1, c.scan_t_s)
    return out


@pytest.mark.parametrize("fps", [10.0, 30.0, 60.0, 90.0, 120.0])
def test_full_scans_come_once_an_interval_whatever_the_frame_rate(fps):
    scans = _scans(fps, 4.0)
    gaps = [b - a for a, b in zip(scans, scans[1:])]
    assert len(set(gaps)) == 1  # evenly spaced
    assert gaps[0] / fps >= 0.25 - 1e-9  # never sooner than the interval ...
    assert gaps[0] / fps < 0.25 + 1 / fps  # ... and the first frame after it
    assert 0.25 * fps <= gaps[0] < 0.25 * fps + 1


def test_at_30_fps_and_without_times_the_default_interval_is_every_8th_frame():
    # what full_scan_every: 8 did: replays without times (and 30 fps runs) read as they did
    assert _scans(30.0, 2.0) == _scans(30.0, 2.0, timed=False) == _scans(30.0, 2.0, interval_s=0.0) == \
        list(range(0, 60, 8))


def test_an_interval_of_zero_counts_frames_whatever_the_times():
    assert _scans(90.0, 1.0, every=5, interval_s=0.0) == list(range(0, 90, 5))


def test_forced_held_and_a_clock_gone_back():
    assert scan_due(Cadence(0, 10.0, forced=True), 10.001, 8, 0.25, NOMINAL)  # a lost track: scanned next frame
    assert not scan_due(Cadence(40, 10.0, held=True), 12.0, 8, 0.25, NOMINAL)  # left for after the send
    assert scan_due(Cadence(3, 10.0), 2.0, 8, 0.25, NOMINAL)  # another run's clock: scanned
    assert not scan_due(Cadence(3, 10.0), 10.2, 8, 0.25, NOMINAL)
    assert scan_due(Cadence(3, 10.0), 10.25, 8, 0.25, NOMINAL)
    assert not scan_due(Cadence(6, None), 10.0, 8, 0.25, NOMINAL)  # no time of the last scan: frames counted
    assert scan_due(Cadence(7, None), 10.0, 8, 0.25, NOMINAL)


@pytest.mark.parametrize("appears", [4, 15])  # early and late in the cycle
def test_at_90_fps_a_newcomer_in_mid_view_shows_within_the_interval_and_fewer_frames_are_scanned(appears):
    cfg = load_config(None)
    interval = cfg.detection.full_scan_interval_s
    bound = math.ceil(interval * 90) + 1
    pipe = Pipeline(cfg.pipeline, track=True)
    found_at, scanned = None, []
    for i, img in enumerate(moving_sequence(appears + bound + 1, newcomer_at=appears)):
        r = pipe.process(img, t_s=100.0 + i / 90)
        if not r.tracked:
            scanned.append(i)
        if i >= appears and len(r.landmarks) == 3:
            found_at = i
            break
        assert len(r.landmarks) == 2
    assert found_at is not None and (found_at - appears) / 90 <= interval + 1 / 90
    before = [i for i in scanned if i < appears]
    assert before == [0]  # every 8th frame would have scanned frame 8 too
    assert scanned[-1] == found_at


@pytest.mark.parametrize("every, interval_s", [(1, 0.0), (8, 0.001)])
def test_when_every_frame_is_scanned_no_scan_is_left_for_after_the_send(every, interval_s):
    cfg = load_config(None)
    cfg = dataclasses.replace(cfg, detection=dataclasses.replace(cfg.detection, full_scan_every=every,
                                                                  full_scan_interval_s=interval_s))
    pipe = Pipeline(cfg.pipeline, track=True)
    for i, img in enumerate(moving_sequence(4)):
        result, finish = pipe.process_scan_later(img, t_s=i / 30)
        assert finish is None and not result.tracked and len(result.landmarks) == 2
