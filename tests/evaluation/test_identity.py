"""Id switches and returns counted against a truth robot column (hand-made detections)."""

from __future__ import annotations

import dataclasses
from typing import List, Optional, Sequence, Tuple

import pytest

from rangebearing.core.types import Landmark
from rangebearing.evaluation.identity import id_report, match_identities
from rangebearing.evaluation.truth import TruthRow

BASE = Landmark(0.5, 0.0, 0.5, 0.0, 60.0, (300.0, 200.0), (300.0, 260.0), 20.0, (290, 190, 20, 80), True)


def lm(range_m: float, bearing_rad: float, track_id: int) -> Landmark:
    return dataclasses.replace(BASE, range_m=range_m, bearing_rad=bearing_rad, track_id=track_id)


def tr(robot: int, range_m: float, bearing_rad: float, findable: Optional[bool] = True) -> TruthRow:
    return TruthRow("f", range_m, bearing_rad, findable=findable, robot=robot)


Frame = Tuple[Sequence[Landmark], Sequence[TruthRow]]


def _still(ids: List[Optional[int]]) -> List[Frame]:
    """One robot at (0.5 m, 0 rad); per frame the track id it is reported with (None: not detected)."""
    return [([] if i is None else [lm(0.5, 0.0, i)], [tr(7, 0.5, 0.0)]) for i in ids]


def test_a_steady_id_has_no_switch():
    rep = id_report(_still([3] * 20))
    assert (rep.landmark_frames, rep.switches, rep.returns, rep.robots) == (20, 0, 0, 1)
    assert rep.passed


def test_a_changed_id_is_one_switch_per_change():
    rep = id_report(_still([3] * 5 + [4] * 5 + [3] * 5))
    assert rep.switches == 2 and rep.switches_per_1000 == 2000 / 15 and not rep.passed


def test_returns_within_fifteen_frames_must_keep_their_id():
    kept = id_report(_still([3] * 5 + [None] * 15 + [3]))
    assert (kept.returns, kept.returns_kept, kept.switches) == (1, 1, 0) and kept.passed
    lost = id_report(_still([3] * 5 + [None] * 4 + [9]))
    assert (lost.returns, lost.returns_kept, lost.switches) == (1, 0, 1) and not lost.passed


def test_a_new_id_after_a_long_absence_is_no_switch():
    rep = id_report(_still([3] * 5 + [None] * 16 + [9] * 3))
    assert (rep.returns, rep.switches) == (0, 0) and rep.passed


def test_detections_without_an_id_are_counted():
    rep = id_report(_still([-1] * 4))
    assert rep.untracked == 4 and not rep.passed


def test_swapped_ids_of_two_robots_count_twice():
    frames = []
    for k in range(10):
        a, b = (1, 2) if k < 5 else (2, 1)
        frames.append(([lm(0.4, 0.2, a), lm(0.9, -0.2, b)], [tr(0, 0.4, 0.2), tr(1, 0.9, -0.2)]))
    assert id_report(frames).switches == 2


def test_matching_uses_range_too_and_skips_hidden_robots():
    # two robots at the same bearing: range decides; a hidden one (not findable) takes nothing
    found = [lm(0.9, 0.011, 5), lm(0.4, 0.01, 4)]
    pairs = match_identities(found, [tr(0, 0.4, 0.0), tr(1, 0.9, 0.0), tr(2, 0.6, 0.012, findable=False)])
    assert sorted((t.robot, f.track_id) for t, f in pairs) == [(0, 4), (1, 5)]
    assert match_identities([lm(0.5, 0.2, 1)], [tr(0, 0.5, 0.0)]) == []  # 11° apart: not this one
    assert match_identities([lm(0.7, 0.0, 1)], [tr(0, 0.5, 0.0)]) == []  # 40 % off in range


def test_published_rates_are_compared_with_the_truths_motion():
    # the robot closes in at 0.3 m/s (0.01 m per frame at 30 fps) and turns left at 0.6 rad/s;
    # the detections say -0.25 m/s and 0.6 rad/s: off by 0.05 m/s and 0
    frames = []
    for k in range(10):
        r, b = 1.0 - 0.01 * k, 0.02 * k
        found = dataclasses.replace(lm(r, b, 1), range_rate_mps=-0.25, bearing_rate_radps=0.6)
        frames.append(([found], [tr(0, r, b)]))
    rep = id_report(frames)
    assert rep.rates == 8  # the first and last frames have no central difference
    assert rep.range_rate_err_mps[0] == pytest.approx(0.05) and rep.bearing_rate_err_radps[1] == pytest.approx(0.0)
