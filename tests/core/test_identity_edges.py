"""A neighbour that leaves the view at its edge and comes back there keeps its id.

A robot driving out at the side stops or turns beyond the edge, unseen; its
track's constant velocity would carry the prediction on outwards, so that when
it comes back in, fast and near, its reading lies outside the gate and it gets a
new id. Given the view's edges, the filter holds such a track at the edge
(:func:`~rangebearing.core.kalman.held_at_edges`).
"""

from __future__ import annotations

import math
from typing import List, Optional, Tuple

import numpy as np
import pytest

from rangebearing.core.identity import empty_state, update
from rangebearing.core.kalman import BEARING, P00, P01, RANGE, RATE, VALUE, held_at_edges

EDGE_RAD = math.atan(320.0 / 634.0)  # the 640-px-wide default camera's half field of view
VIEW = (-EDGE_RAD, EDGE_RAD)
RADIUS_M = 0.0175


def _out_and_back(range_m: float, speed_mps: float, turn_after: int, side: float,
                  view: Optional[Tuple[float, float]], seed: int = 0) -> Tuple[int, List[int]]:
    """Frames unseen and the ids given to a robot that drives out at a side, turns ``turn_after``
    frames after it was last findable, and drives back in (60 % of its width in view: read)."""
    rng = np.random.default_rng(seed)
    state = empty_state()
    b, rate, half = side * (EDGE_RAD - 0.25), side * speed_mps / range_m, RADIUS_M / range_m
    ids: List[int] = []
    unseen = gone = 0
    while True:
        b += rate / 30.0
        visible = min(1.0, max(0.0, (EDGE_RAD - (side * b - half)) / (2 * half)))
        if visible >= 0.6:
            if rate * side < 0 and side * b < EDGE_RAD - 0.2:
                return unseen, ids
            state, out = update(state, [range_m * (1 + rng.normal(0, 0.004))], [b + rng.normal(0, 0.0015)],
                                [0.004 * range_m], [0.0015], visible=[visible], view_rad=view)
            ids.append(int(out.track_id[0]))
        else:
            state, _ = update(state, [], [], [], [], view_rad=view)
            unseen += 1
            gone += 1
            if gone >= turn_after and rate * side > 0:
                rate = -rate


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("range_m,speed_mps", [(0.3, 0.35), (0.5, 0.35), (0.3, 0.5), (1.0, 0.5), (1.8, 0.2)])
@pytest.mark.parametrize("turn_after", [2, 4, 6])
def test_a_robot_back_from_beyond_the_edge_keeps_its_id(side, range_m, speed_mps, turn_after):
    unseen, ids = _out_and_back(range_m, speed_mps, turn_after, side, VIEW)
    assert 1 <= unseen <= 15
    assert set(ids) == {0}


def test_without_the_view_a_fast_near_return_gets_a_new_id():
    # what the edge hold is for: the prediction runs on outwards and the gate misses the return
    unseen, ids = _out_and_back(0.3, 0.35, 2, 1.0, None)
    assert unseen <= 15 and len(set(ids)) == 2


def test_only_tracks_predicted_out_of_the_view_and_moving_out_are_held():
    s = np.zeros((3, 2, 5))
    s[:, RANGE, VALUE] = 0.5
    s[:, BEARING, P00] = 1e-6
    s[:, BEARING, P01] = 1e-5
    s[0, BEARING, VALUE], s[0, BEARING, RATE] = EDGE_RAD - 0.01, 0.6  # leaving on the left
    s[1, BEARING, VALUE], s[1, BEARING, RATE] = EDGE_RAD + 0.05, -0.6  # coming back in: left alone
    s[2, BEARING, VALUE], s[2, BEARING, RATE] = 0.0, 0.6  # in the middle
    held = held_at_edges(s, 1 / 30, VIEW, 0.035)
    assert held[0, BEARING, VALUE] == EDGE_RAD and held[0, BEARING, RATE] == 0.0 and held[0, BEARING, P01] == 0.0
    assert held[0, BEARING, P00] == pytest.approx((0.035 / 0.5) ** 2)
    np.testing.assert_array_equal(held[1:], s[1:])
    still = s[2:]
    assert held_at_edges(still, 1 / 30, VIEW, 0.035) is still  # nothing held: no copy
    s[2, BEARING, VALUE], s[2, BEARING, RATE] = -EDGE_RAD + 0.01, -0.6  # leaving on the right
    assert held_at_edges(s, 1 / 30, VIEW, 0.035)[2, BEARING, VALUE] == -EDGE_RAD


def test_the_small_path_and_the_numpy_path_hold_alike():
    state_a = state_b = empty_state()
    for k in range(12):
        b = EDGE_RAD - 0.05 + 0.02 * k
        z = ([0.5], [b], [0.002], [0.0015]) if b < EDGE_RAD else ([], [], [], [])
        state_a, out_a = update(state_a, *z, view_rad=VIEW)
        state_b, out_b = update(state_b, *z, view_rad=VIEW, small=False)
        np.testing.assert_array_equal(out_a.track_id, out_b.track_id)
        np.testing.assert_allclose(state_a.s, state_b.s, rtol=1e-9, atol=1e-12)
    assert state_a.x[0, BEARING, 0] == pytest.approx(EDGE_RAD)


def test_a_newcomer_at_the_edge_does_not_keep_a_hidden_robots_id():
    # robot 0 drives out at the right edge at 0.87 m and waits there; robot 1 comes in at that edge at 0.75 m
    # and takes robot 0's held track (inside its grown gate); robot 0 comes back in: it gets its id back, and
    # robot 1 goes on under the id it would have had (one switch, where its coming in could not be told apart)
    state = empty_state()
    edge = -EDGE_RAD + 0.02
    given = {0: [], 1: []}
    for k in range(40):
        robots = []
        if k < 6:
            robots.append((0, 0.87, edge + 0.04 - 0.01 * k))
        if k >= 9:
            robots.append((1, 0.75 - 0.003 * (k - 9), edge + 0.01 * (k - 9)))
        if k >= 14:
            robots.append((0, 0.85, edge + 0.01 * (k - 14)))
        state, out = update(state, [r for _, r, _ in robots], [b for _, _, b in robots],
                            [0.004 * r for _, r, _ in robots], [0.0015] * len(robots), view_rad=VIEW)
        for (robot, _, _), tid in zip(robots, out.track_id.tolist()):
            given[robot].append(tid)
    assert set(given[0]) == {0}
    assert given[1][:5] == [0] * 5 and set(given[1][5:]) == {1}
    assert state.next_id == 2  # no id made twice
