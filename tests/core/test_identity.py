"""Track ids and rates from hand-made readings (no images)."""

from __future__ import annotations

import math
from typing import List, Optional, Sequence, Tuple

import numpy as np
import pytest

from rangebearing.core.identity import Identified, IdentityParams, IdentityState, empty_state, update

P = IdentityParams()
DT = 1.0 / 30.0


def _frame(state: IdentityState, readings: Sequence[Tuple[float, float]], t_s: Optional[float] = None,
           sigma: Tuple[float, float] = (0.003, 0.002)) -> Tuple[IdentityState, Identified]:
    r = [a for a, _ in readings]
    b = [c for _, c in readings]
    return update(state, r, b, [sigma[0]] * len(r), [sigma[1]] * len(r), t_s, P)


def test_one_still_neighbour_keeps_its_id_and_has_no_rate_at_first():
    state = empty_state()
    ids = []
    for i in range(5):
        state, out = _frame(state, [(0.5, 0.1)])
        ids.append(int(out.track_id[0]))
        if i + 1 < P.rate_after_updates:
            assert math.isnan(out.range_rate_mps[0]) and math.isnan(out.bearing_rate_radps[0])
        else:
            assert abs(out.range_rate_mps[0]) < 1e-9 and abs(out.bearing_rate_radps[0]) < 1e-9
    assert ids == [0] * 5


@pytest.mark.parametrize("gap, same", [(1, True), (15, True), (16, False), (30, False)])
def test_an_id_survives_fifteen_hidden_frames_and_no_more(gap, same):
    state = empty_state()
    for _ in range(10):
        state, out = _frame(state, [(0.6, -0.2)])
    first = int(out.track_id[0])
    for _ in range(gap):
        state, out = _frame(state, [])
    state, out = _frame(state, [(0.6, -0.2)])
    assert (int(out.track_id[0]) == first) is same
    if not same:
        assert int(out.track_id[0]) > first


def test_ids_are_never_reused():
    rng = np.random.default_rng(3)
    state = empty_state()
    seen_ids: List[int] = []
    alive = set()
    present = np.ones(5, dtype=bool)
    for _ in range(600):
        # neighbours, far apart in bearing, appear and vanish for stretches of ~20 frames
        present ^= rng.random(5) < 0.05
        readings = [(0.5 + 0.1 * k, -0.4 + 0.2 * k) for k in range(5) if present[k]]
        state, out = _frame(state, readings)
        for tid in out.track_id.tolist():
            if tid not in alive:
                assert tid not in seen_ids  # a fresh id is fresh
                seen_ids.append(tid)
                alive.add(tid)
        alive &= set(state.ids.tolist())
    assert seen_ids == sorted(seen_ids) and len(seen_ids) == len(set(seen_ids)) > 5


def test_the_first_id_of_a_run_can_be_chosen():
    state, out = _frame(empty_state(first_id=100), [(0.4, 0.0), (0.9, 0.3)])
    assert sorted(out.track_id.tolist()) == [100, 101] and state.next_id == 102


def _crossing(r_a: float, r_b: float, frames: int, seed: int, occlude: bool):
    """Two neighbours crossing in bearing (A right to left, B left to right), noisy readings."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(frames):
        t = i * DT
        a = (r_a + 0.05 * t, -0.35 + 0.7 * t)  # 0.7 rad/s across the view
        b = (r_b - 0.05 * t, 0.35 - 0.7 * t)
        seen = {"A": a, "B": b}
        if occlude and abs(a[1] - b[1]) < 0.06:  # the nearer one hides the farther one
            del seen["A" if a[0] > b[0] else "B"]
        noisy = {k: (v[0] + rng.normal(0, 0.003), v[1] + rng.normal(0, 0.002)) for k, v in seen.items()}
        out.append(noisy)
    return out


@pytest.mark.parametrize("r_a, r_b", [(0.45, 0.95), (0.60, 0.62), (0.70, 0.70)])
@pytest.mark.parametrize("occlude", [False, True])
def test_crossing_neighbours_do_not_swap_ids(r_a, r_b, occlude):
    for seed in range(3):
        state = empty_state()
        owner = {}
        for frame in _crossing(r_a, r_b, 30, seed, occlude):
            names = sorted(frame)  # readings in a fixed but arbitrary order
            state, out = _frame(state, [frame[k] for k in names])
            for k, tid in zip(names, out.track_id.tolist()):
                assert owner.setdefault(k, tid) == tid, f"{k} changed id (seed {seed})"
        assert len(set(owner.values())) == 2


def test_input_order_does_not_change_who_gets_which_id():
    a, b, c = (0.4, 0.3), (0.8, 0.0), (1.2, -0.3)
    s1, s2 = empty_state(), empty_state()
    for i in range(10):
        d = 0.01 * i
        s1, o1 = _frame(s1, [(a[0], a[1] + d), (b[0], b[1] + d), (c[0], c[1] + d)])
        s2, o2 = _frame(s2, [(c[0], c[1] + d), (a[0], a[1] + d), (b[0], b[1] + d)])
        if i == 0:
            first1, first2 = o1.track_id.tolist(), o2.track_id.tolist()
    assert o1.track_id.tolist() == first1
    assert o2.track_id.tolist() == first2


@pytest.mark.parametrize("jitter", [0.0, 0.4])
def test_rates_converge_to_a_constant_velocity(jitter):
    """Range closes at 0.3 m/s and bearing turns at 0.5 rad/s; frame times jitter by up to ±40 %."""
    rng = np.random.default_rng(11)
    state = empty_state()
    t, last = 100.0, None
    errs, naive = [], []
    for i in range(90):
        t += DT * (1.0 + jitter * rng.uniform(-1.0, 1.0))
        r_true = 1.2 - 0.3 * (t - 100.0)
        b_true = -0.4 + 0.5 * (t - 100.0)
        sigma = (0.004 * r_true, 0.002)
        z = (r_true + rng.normal(0, sigma[0]), b_true + rng.normal(0, sigma[1]))
        state, out = _frame(state, [z], t, sigma)
        assert out.track_id.tolist() == [0]
        if i >= 60:
            errs.append((out.range_rate_mps[0] + 0.3, out.bearing_rate_radps[0] - 0.5))
            dt = t - last[0]
            naive.append(((z[0] - last[1][0]) / dt + 0.3, (z[1] - last[1][1]) / dt - 0.5))
        last = (t, z)
    e, d = np.abs(np.array(errs)).mean(axis=0), np.abs(np.array(naive)).mean(axis=0)
    assert e[0] < 0.02 and e[1] < 0.05  # m/s, rad/s
    assert (e < 0.6 * d).all()  # well below differencing two readings


def test_without_timestamps_the_nominal_interval_is_used():
    state = empty_state()
    for i in range(40):
        state, out = _frame(state, [(1.0 - 0.2 * i * DT, 0.0)], t_s=None, sigma=(0.0005, 0.0005))
    assert out.range_rate_mps[0] == pytest.approx(-0.2, abs=0.01)
    # the same readings stamped twice as far apart halve the rate
    state = empty_state()
    for i in range(40):
        state, out = _frame(state, [(1.0 - 0.2 * i * DT, 0.0)], t_s=2 * i * DT, sigma=(0.0005, 0.0005))
    assert out.range_rate_mps[0] == pytest.approx(-0.1, abs=0.01)


def test_a_far_jump_starts_a_new_track_and_a_zero_sigma_is_floored():
    state = empty_state()
    for _ in range(5):
        state, out = update(state, [0.5], [0.0], [0.0], [0.0], None, P)  # sigma 0: floors apply
    assert out.track_id.tolist() == [0]
    state, out = update(state, [0.5], [0.5], [0.0], [0.0], None, P)  # 29° away in one frame
    assert out.track_id.tolist() == [1]


def test_a_landmark_read_twice_is_one_neighbour():
    state = empty_state()
    for _ in range(5):
        state, out = _frame(state, [(0.6, 0.1)])
    state, out = _frame(state, [(0.6, 0.1), (0.61, 0.12)])  # split by the detector: 1.2 cm apart at 0.6 m
    assert out.track_id.tolist() == [0, 0] and state.size == 1
    state, out = _frame(state, [(0.6, 0.1), (0.6, 0.2)])  # 6 cm apart: another robot
    assert out.track_id.tolist() == [0, 1]


def test_a_partly_seen_reading_cannot_bend_the_rate():
    def run(visible: float) -> float:
        state = empty_state()
        for _ in range(20):
            state, out = update(state, [0.6], [0.1], [0.003], [0.0008], None, P, [1.0])
        state, out = update(state, [0.6], [0.107], [0.003], [0.0008], None, P, [visible])  # 0.4° off
        return float(out.bearing_rate_radps[0])
    assert abs(run(0.45)) < 0.3 * abs(run(1.0))
