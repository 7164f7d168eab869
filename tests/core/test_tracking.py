"""Tracking gives the same readings as full-frame search, and finds newcomers within the bound."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from rangebearing import Pipeline, load_config
from rangebearing.sources.recorded import iter_recorded
from rangebearing.synth import Imaging, LandmarkPose, Scene, render

ROOT = Path(__file__).resolve().parents[2]
NOISE = Imaging(blur_sigma_px=0.5, read_noise=0.004, shot_noise=0.0005)
# The stated tolerance between tracked and full-frame readings of the same frame.
RANGE_TOL, BEARING_TOL_RAD = 0.003, math.radians(0.03)


def moving_sequence(frames: int, newcomer_at: int = -1, seed: int = 0):
    """Two landmarks drifting across the view; a third appears at ``newcomer_at``."""
    rng = np.random.default_rng(seed)
    for i in range(frames):
        lms = [LandmarkPose(0.5 + 0.004 * i, 0.30 - 0.012 * i), LandmarkPose(1.1 - 0.006 * i, -0.25 + 0.008 * i)]
        if 0 <= newcomer_at <= i:
            lms.append(LandmarkPose(0.7, 0.02))
        yield render(Scene(landmarks=tuple(lms), wall_distance_m=2.5, imaging=NOISE), rng)


def assert_same_readings(frames, max_landmarks=None):
    cfg = load_config(None)
    if max_landmarks is not None:  # more than the default (what fits one datagram): the pipeline can find them
        cfg = dataclasses.replace(cfg, detection=dataclasses.replace(cfg.detection, max_landmarks=max_landmarks))
    full, tracker = Pipeline(cfg.pipeline, track=False), Pipeline(cfg.pipeline, track=True)
    tracked = 0
    for img in frames:
        a, b = full.process(img), tracker.process(img)
        tracked += b.tracked
        assert len(a.landmarks) == len(b.landmarks)
        by_bearing = lambda r: sorted(r.landmarks, key=lambda lm: lm.bearing_rad)  # noqa: E731
        for x, y in zip(by_bearing(a), by_bearing(b)):
            assert y.range_m == pytest.approx(x.range_m, rel=RANGE_TOL)
            assert y.bearing_rad == pytest.approx(x.bearing_rad, abs=BEARING_TOL_RAD)
    return tracked


def test_tracking_matches_full_search_on_the_bundled_clip():
    frames = [img for _, img in iter_recorded(ROOT / "samples" / "clip")]
    assert assert_same_readings(frames) >= len(frames) * 3 // 4


def test_tracking_matches_full_search_on_a_moving_sequence():
    assert assert_same_readings(list(moving_sequence(24))) >= 18


def crowd(frames: int, n: int = 10, seed: int = 1):
    """``n`` landmarks side by side across the whole view, swaying together."""
    rng = np.random.default_rng(seed)
    bearings = np.linspace(-0.40, 0.40, n)
    for i in range(frames):
        sway = 0.01 * math.sin(i / 3.0)
        lms = tuple(LandmarkPose(0.5 if k % 2 else 1.2, float(b) + sway) for k, b in enumerate(bearings))
        yield render(Scene(landmarks=lms, wall_distance_m=2.5, imaging=NOISE), rng)


def test_tracking_matches_full_search_with_ten_landmarks_side_by_side():
    # neighbours reach into each other's windows: their bands must not pull the centroids
    assert assert_same_readings(list(crowd(12)), max_landmarks=10) >= 9


@pytest.mark.parametrize("appears", range(3, 3 + 8))  # every phase of the full-scan cycle
def test_a_newcomer_is_found_within_full_scan_every_frames(appears):
    cfg = load_config(None)
    bound = cfg.detection.full_scan_every
    pipe = Pipeline(cfg.pipeline, track=True)
    found_at = None
    for i, img in enumerate(moving_sequence(appears + bound + 1, newcomer_at=appears)):
        n = len(pipe.process(img).landmarks)
        if i >= appears and n == 3:
            found_at = i
            break
        assert n == 2  # never more than are there
    assert found_at is not None and found_at - appears < bound


def test_a_lost_landmark_is_scanned_for_on_the_same_frame_and_the_next():
    cfg = dataclasses.replace(load_config(None))
    pipe = Pipeline(cfg.pipeline, track=True)
    still = Scene(landmarks=(LandmarkPose(0.6, 0.25),), wall_distance_m=2.5)
    jumped = Scene(landmarks=(LandmarkPose(0.6, -0.25),), wall_distance_m=2.5)
    pipe.process(render(still))
    assert pipe.process(render(still)).tracked
    lost = pipe.process(render(jumped))  # out of its window: the frame is scanned whole, its reading not missed
    assert not lost.tracked and len(lost.landmarks) == 1
    assert lost.landmarks[0].bearing_rad == pytest.approx(-0.25, abs=0.01)
    again = pipe.process(render(jumped))  # what lost it may still be going on: scanned whole again
    assert not again.tracked and len(again.landmarks) == 1
    assert again.landmarks[0].track_id == lost.landmarks[0].track_id
    assert pipe.process(render(jumped)).tracked


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_a_landmark_running_off_the_frame_edge_is_cut_there_as_a_full_scan_has_it(side):
    # about 5 px a frame towards the left (side 1) or right edge, until less than half of it is left
    rng = np.random.default_rng(3)
    frames = [render(Scene(landmarks=(LandmarkPose(1.0, side * (0.415 + 0.008 * i)),), wall_distance_m=2.5,
                           imaging=NOISE), rng) for i in range(12)]
    cfg = load_config(None)
    full, tracker = Pipeline(cfg.pipeline, track=False), Pipeline(cfg.pipeline, track=True)
    seen = []
    for img in frames:
        a, b = full.process(img), tracker.process(img)
        assert len(b.landmarks) <= len(a.landmarks)  # a tracked reading only where a full scan has one
        if b.tracked and a.landmarks and b.landmarks:
            x, y = a.landmarks[0], b.landmarks[0]
            assert y.visible == pytest.approx(x.visible, abs=0.06)
            assert y.bearing_rad == pytest.approx(x.bearing_rad, abs=math.radians(0.1))
            assert y.range_m == pytest.approx(x.range_m, rel=0.01)
            seen.append(y.visible)
    assert len(seen) >= 4 and seen[0] > 0.95 and min(seen) < 0.75  # followed from whole to well cut


def test_landmarks_crossing_in_the_image_are_measured_as_a_full_scan_has_them():
    # a near landmark passes in front of a far one: windows that meet take in parts of both, and the one
    # behind is partly hidden as only a full scan measures it
    rng = np.random.default_rng(1)
    frames = [render(Scene(landmarks=(LandmarkPose(0.6, -0.08 + 0.006 * i), LandmarkPose(1.2, 0.08 - 0.006 * i)),
                           wall_distance_m=2.5, imaging=NOISE), rng) for i in range(24)]
    cfg = load_config(None)
    full, tracker = Pipeline(cfg.pipeline, track=False), Pipeline(cfg.pipeline, track=True)
    tracked = 0
    for img in frames:
        a, b = full.process(img), tracker.process(img)
        tracked += b.tracked
        assert len(b.landmarks) <= len(a.landmarks)  # never a landmark a full scan does not have
        for y in b.landmarks:
            x = min(a.landmarks, key=lambda lm: abs(lm.bearing_rad - y.bearing_rad))
            assert y.range_m == pytest.approx(x.range_m, rel=0.01)
            assert y.bearing_rad == pytest.approx(x.bearing_rad, abs=math.radians(0.1))
    assert tracked >= 11  # apart from the crossing itself (scanned from the frame its predicted columns meet)


def test_a_landmark_coming_out_from_behind_a_nearer_one_is_found_as_it_comes_out():
    # a near landmark passes in front of a far one standing still: the far one leaves the tracks while hidden
    rng = np.random.default_rng(4)
    frames = [render(Scene(landmarks=(LandmarkPose(0.5, -0.16 + 0.012 * i), LandmarkPose(1.3, 0.0)),
                           wall_distance_m=2.5, imaging=NOISE), rng) for i in range(28)]
    cfg = load_config(None)
    full, tracker = Pipeline(cfg.pipeline, track=False), Pipeline(cfg.pipeline, track=True)
    counts = [(len(full.process(img).landmarks), len(tracker.process(img).landmarks)) for img in frames]
    hidden = [i for i, (a, _) in enumerate(counts) if a == 1]
    assert hidden and max(hidden) < len(frames) - 8  # hidden for a while, then out again for a full-scan cycle
    out = max(hidden) + 1
    assert all(b == a for a, b in counts[out + 1:])  # found at most a frame after a full scan sees it again


def test_a_full_scan_hands_each_landmark_the_velocity_of_the_track_it_continues():
    from rangebearing.core.detect import BandCentroids
    from rangebearing.core.scans import rescanned
    from rangebearing.core.tracking import Track

    def bands(x: float, w: int = 20) -> BandCentroids:
        return BandCentroids((x, 100.0), (x, 140.0), (int(x) - w // 2, 95, w, 10), (int(x) - w // 2, 135, w, 10),
                             100.0, 100.0, 50.0, 50.0)

    moving = Track(bands(200.0), (3.0, 0.0))  # 3 px a frame to the right
    lost = Track(bands(400.0), (-2.0, 0.0))  # lost in the frame before the scan: two frames old
    out = rescanned([moving], [bands(203.5), bands(396.0), bands(50.0), bands(206.0, 60)], [lost])
    assert out[0].velocity_px == pytest.approx((3.5, 0.0))
    assert out[1].velocity_px == pytest.approx((-2.0, 0.0))
    assert out[2].velocity_px == (0.0, 0.0)  # a newcomer
    assert out[3].velocity_px == (0.0, 0.0)  # three times as wide: another landmark
