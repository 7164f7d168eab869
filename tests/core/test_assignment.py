"""The assignment solver against brute force, and the gate."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from rangebearing.core.assignment import assign_gated, hungarian


def _best(c: np.ndarray) -> float:
    n, m = c.shape
    if n <= m:
        return min(sum(c[i, p[i]] for i in range(n)) for p in itertools.permutations(range(m), n))
    return min(sum(c[p[j], j] for j in range(m)) for p in itertools.permutations(range(n), m))


@pytest.mark.parametrize("shape", [(1, 1), (2, 2), (3, 3), (2, 4), (4, 2), (5, 5), (3, 6)])
def test_hungarian_finds_the_least_total_cost(shape):
    rng = np.random.default_rng(sum(shape))
    for trial in range(40):
        c = rng.normal(size=shape) if trial % 2 else rng.integers(0, 3, shape).astype(float)  # ties too
        a = hungarian(c)
        assert (a >= 0).sum() == min(shape)
        assert len(set(a[a >= 0].tolist())) == min(shape)
        assert sum(c[i, a[i]] for i in range(shape[0]) if a[i] >= 0) == pytest.approx(_best(c), abs=1e-12)


def test_hungarian_by_hand():
    # greedy takes (0, 0) = 1 and is left with (1, 1) = 10; the optimum crosses over: 2 + 3
    c = np.array([[1.0, 2.0], [3.0, 10.0]])
    assert hungarian(c).tolist() == [1, 0]
    assert hungarian(np.zeros((0, 3))).tolist() == []
    assert hungarian(np.zeros((2, 0))).tolist() == [-1, -1]


def test_unambiguous_pairs_need_no_search_and_gate_holds():
    c = np.array([[0.5, 99.0, 99.0], [99.0, 99.0, 2.0]])
    rows, cols = assign_gated(c, gate=16.0)
    assert sorted(zip(rows.tolist(), cols.tolist())) == [(0, 0), (1, 2)]
    rows, cols = assign_gated(np.full((2, 2), 20.0), gate=16.0)
    assert rows.size == cols.size == 0


def test_overlapping_gates_are_solved_globally():
    # track 0 is nearest to detection 0, but taking it leaves track 1 unmatched;
    # the most gated pairs first: (0, 1) and (1, 0)
    c = np.array([[1.0, 3.0], [2.0, np.nan]])
    rows, cols = assign_gated(c, gate=16.0)
    assert sorted(zip(rows.tolist(), cols.tolist())) == [(0, 1), (1, 0)]
    # among equally many pairs, the least total cost: 1 + 1 beats 2 + 2
    c = np.array([[1.0, 2.0, 50.0], [2.0, 1.0, 50.0], [50.0, 50.0, 0.0]])
    rows, cols = assign_gated(c, gate=16.0)
    assert sorted(zip(rows.tolist(), cols.tolist())) == [(0, 0), (1, 1), (2, 2)]


def test_assign_gated_matches_brute_force_on_random_gates():
    rng = np.random.default_rng(7)
    for _ in range(200):
        n, m = (int(v) for v in rng.integers(1, 6, 2))
        c = rng.uniform(0.0, 30.0, (n, m))
        rows, cols = assign_gated(c, gate=16.0)
        assert len(set(rows.tolist())) == rows.size and len(set(cols.tolist())) == cols.size
        assert (c[rows, cols] <= 16.0).all()
        # brute force over all partial matchings inside the gate: (most pairs, least cost)
        best = (0, 0.0)
        for k in range(1, min(n, m) + 1):
            for rs in itertools.combinations(range(n), k):
                for cs in itertools.permutations(range(m), k):
                    cost = c[list(rs), list(cs)]
                    if (cost <= 16.0).all() and (k, -cost.sum()) > (best[0], -best[1]):
                        best = (k, float(cost.sum()))
        assert rows.size == best[0]
        assert c[rows, cols].sum() == pytest.approx(best[1])


def test_an_infinite_gate_with_overlapping_candidates_stays_finite():
    # every finite cost counts; the solver must not see inf - inf (it once did)
    c = np.array([[1.0, 2.0], [1.5, np.inf]])
    rows, cols = assign_gated(c, gate=np.inf)
    assert sorted(zip(rows.tolist(), cols.tolist())) == [(0, 1), (1, 0)]
