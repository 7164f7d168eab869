"""Harder crossings from hand-made readings: dense crossings, equal ranges, merged and partly hidden readings.

Each sequence moves robots along straight paths in (range, bearing) at 30 fps
and makes the readings a crowd-proof detector gives: a landmark covered by a
nearer one is partly hidden (its reading shifts towards its visible part and
says ``visible`` < 1) or not read at all; two landmarks touching in the image
at similar ranges may be read as one merged reading between them, 5-14 % short
in range (issue 8). Ids are scored as ``replay --truth`` scores them
(:func:`~rangebearing.evaluation.identity.id_report`).
"""

from __future__ import annotations

import math
from typing import List, Sequence, Tuple

import numpy as np
import pytest

from rangebearing.core.identity import empty_state
from rangebearing.core.identity_landmarks import identify
from rangebearing.core.types import Landmark
from rangebearing.evaluation.identity import IdReport, id_report
from rangebearing.evaluation.truth import TruthRow

RADIUS_M = 0.0175
Path = Tuple[float, float, float, float]  # range from, range to, bearing from, bearing to


def _reading(r: float, b: float, visible: float) -> Landmark:
    return Landmark(r, b, r, 0.0, 50.0, (0.0, 0.0), (0.0, 0.0), 20.0, (0, 0, 1, 1), True,
                    range_sigma_m=0.004 * r, bearing_sigma_rad=0.0015, visible=visible)


def _visible(r: np.ndarray, b: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Per landmark the fraction not covered by nearer ones, and the centre bearing of that part."""
    half = RADIUS_M / r
    vis, centre = np.ones(r.size), b.copy()
    for i in range(r.size):
        lo, hi = b[i] - half[i], b[i] + half[i]
        segs = [(lo, hi)]
        for j in np.nonzero(r < r[i])[0]:  # cut what each nearer landmark covers out of the seen parts
            jl, jh = b[j] - half[j], b[j] + half[j]
            cut = []
            for s0, s1 in segs:
                if jh <= s0 or jl >= s1:
                    cut.append((s0, s1))
                    continue
                cut.extend(([(s0, jl)] if jl > s0 else []) + ([(jh, s1)] if jh < s1 else []))
            segs = cut
        seen = sum(s1 - s0 for s0, s1 in segs)
        vis[i] = seen / (hi - lo)
        if seen > 0:
            centre[i] = sum(0.5 * (s0 + s1) * (s1 - s0) for s0, s1 in segs) / seen
    return vis, centre


def _run(paths: Sequence[Path], frames: int, seed: int, merge: float = 0.0, miss: float = 0.0) -> IdReport:
    rng = np.random.default_rng(seed)
    state, scored = empty_state(), []
    for k in range(frames):
        u = k / (frames - 1)
        r = np.array([p[0] + u * (p[1] - p[0]) for p in paths])
        b = np.array([p[2] + u * (p[3] - p[2]) for p in paths])
        vis, centre = _visible(r, b)
        truth = [TruthRow(str(k), float(r[i]), float(b[i]), float(vis[i]), findable=bool(vis[i] >= 0.6), robot=i)
                 for i in range(len(paths))]
        readings: List[Landmark] = []
        merged = set()
        for i in range(len(paths)):
            for j in range(i + 1, len(paths)):
                touching = abs(b[i] - b[j]) < 1.3 * RADIUS_M * (1 / r[i] + 1 / r[j])
                if (touching and abs(r[i] - r[j]) < 0.15 * r[i] and min(vis[i], vis[j]) > 0.3
                        and not merged & {i, j} and rng.random() < merge):
                    w = vis[i] / (vis[i] + vis[j])
                    short = rng.uniform(0.86, 0.95)
                    readings.append(_reading(short * (w * r[i] + (1 - w) * r[j]), w * centre[i] + (1 - w) * centre[j],
                                             0.5))
                    merged |= {i, j}
        for i in range(len(paths)):
            if i in merged or vis[i] < 0.55 or rng.random() < miss:
                continue
            readings.append(_reading(r[i] * (1 + rng.normal(0, 0.004)), centre[i] + rng.normal(0, 0.0015),
                                     float(vis[i])))
        rng.shuffle(readings)
        state, labelled = identify(state, readings, k / 30.0)
        scored.append((labelled, truth))
    return id_report(scored)


def _assert_kept(rep: IdReport) -> None:
    assert rep.landmark_frames > 0
    assert rep.switches == 0, rep
    assert rep.returns_kept == rep.returns, rep


# Robots' bodies (~10 cm) cannot pass through each other: crossing robots are at least that far apart in range.
# Four robots crossing at one moment in the middle of the view: two pairs, 12 cm apart in range each, at
# 0.5 and 0.9 m, all sweeping 0.5 rad in 1.5 s (the near pair hides the far pair, each pair's far one
# passes behind its near one)
DENSE: Sequence[Path] = ((0.50, 0.52, 0.25, -0.25), (0.64, 0.62, -0.25, 0.25),
                         (0.88, 0.90, 0.30, -0.20), (1.00, 1.02, -0.20, 0.30))
# nearly equal ranges (10 cm apart at 0.7 m: range alone cannot tell them apart while one hides the other)
EQUAL: Sequence[Path] = ((0.70, 0.70, 0.30, -0.30), (0.80, 0.80, -0.30, 0.30))
CLOSE: Sequence[Path] = ((0.62, 0.66, -0.25, 0.25), (0.72, 0.70, 0.25, -0.25))  # touching while passing


@pytest.mark.parametrize("seed", range(4))
def test_four_robots_crossing_at_once_keep_their_ids(seed):
    _assert_kept(_run(DENSE, 45, seed, miss=0.03))


@pytest.mark.parametrize("seed", range(4))
def test_robots_at_equal_ranges_crossing_keep_their_ids(seed):
    rep = _run(EQUAL, 45, seed)
    _assert_kept(rep)
    assert rep.returns >= 1  # one hid the other (they cannot both be nearest): it came back with its id


@pytest.mark.parametrize("seed", range(4))
def test_merged_and_partly_hidden_readings_while_crossing_do_not_swap_ids(seed):
    """Touching landmarks are read as one merged reading half the time while they pass each other."""
    _assert_kept(_run(CLOSE, 45, seed, merge=0.5, miss=0.03))


def test_the_merged_case_is_exercised():
    """The sequences above do contain merged and partly hidden readings (else they would prove nothing)."""
    with_merges, without = _run(CLOSE, 45, 0, merge=1.0), _run(CLOSE, 45, 0, merge=0.0)
    assert with_merges.landmark_frames < without.landmark_frames - 4  # merged readings match no robot
    assert math.isfinite(without.landmark_frames)


def test_a_robot_hidden_behind_another_for_up_to_fifteen_frames_keeps_its_id():
    """The far robot drifts behind the near one, 0.16 rad/s slower: unseen for 12-15 frames in a row."""
    paths = ((0.50, 0.50, 0.20, -0.20), (1.00, 1.00, 0.081, -0.081))
    hidden = [_visible(np.array([p[0] for p in paths]), np.array([p[2] + u * (p[3] - p[2]) for p in paths]))[0][1]
              < 0.55 for u in np.linspace(0.0, 1.0, 45)]
    longest = max(len(run) for run in "".join("h" if h else "." for h in hidden).split("."))
    assert 12 <= longest <= 15
    for seed in range(4):
        rep = _run(paths, 45, seed)
        assert rep.returns >= 1 and rep.returns_kept == rep.returns and rep.switches == 0, rep


SIDE_BY_SIDE: Sequence[Path] = ((1.60, 1.60, 0.235, 0.235), (1.70, 1.70, 0.250, 0.250))  # still, touching


def test_a_merged_reading_does_not_drag_one_robots_track_onto_its_neighbour():
    """Two still robots touching in the image at 1.6 and 1.7 m, read as one merged reading (between them,
    5-14 % short) in half the frames. A merged reading moves neither track; fed to one of them it dragged
    that track onto the neighbour (19 id switches per 1,000 landmark-frames on these seeds before; 3 now)."""
    reps = [_run(SIDE_BY_SIDE, 90, seed, merge=0.5, miss=0.03) for seed in range(16)]
    frames, switches = sum(r.landmark_frames for r in reps), sum(r.switches for r in reps)
    returns, kept = sum(r.returns for r in reps), sum(r.returns_kept for r in reps)
    assert frames > 1000 and returns > 300  # both robots read separately often, and often merged
    assert 1000 * switches / frames <= 5.0, (switches, frames)
    assert kept >= 0.99 * returns, (kept, returns)
