"""The float path of the identity filter (core/identity_small.py) gives the numpy path's ids and values."""

from __future__ import annotations

import numpy as np
import pytest

from rangebearing.core import identity_small
from rangebearing.core.identity import IdentityParams, empty_state, update

P = IdentityParams()


def _sequence(seed: int, frames: int = 60):
    """Robots moving in range and bearing, some crossing, with misses, twins, strays, partly seen readings."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 6))
    r0, b0 = rng.uniform(0.3, 2.0, n), rng.uniform(-0.4, 0.4, n)
    vr, vb = rng.uniform(-0.3, 0.3, n), rng.uniform(-0.3, 0.3, n)
    for k in range(frames):
        t = k / 30.0
        rows = []
        for i in range(n):
            if rng.random() < 0.15:  # missed or hidden this frame
                continue
            r, b = r0[i] + vr[i] * t, b0[i] + vb[i] * t
            rows.append((r * (1 + rng.normal(0, 0.004)), b + rng.normal(0, 0.002), 0.004 * r, 0.002,
                         1.0 if rng.random() < 0.8 else float(rng.uniform(0.5, 1.0))))
            if rng.random() < 0.05:  # read twice (the detector split it)
                rows.append((r * 1.01, b + 0.01 / r, 0.004 * r, 0.002, 1.0))
        if rng.random() < 0.05:  # a stray reading
            rows.append((float(rng.uniform(0.3, 2.0)), float(rng.uniform(-0.4, 0.4)), 0.01, 0.003, 1.0))
        rng.shuffle(rows)
        yield (k / 30.0 if seed % 2 else None), rows


@pytest.mark.parametrize("seed", range(40))
def test_the_float_path_gives_the_numpy_paths_ids_and_values(seed, monkeypatch):
    taken = []
    real = identity_small.update_small

    def counted(*args, **kwargs):
        out = real(*args, **kwargs)
        taken.append(out is not None)
        return out

    monkeypatch.setattr("rangebearing.core.identity.update_small", counted)
    fast, ref = empty_state(), empty_state()
    for t_s, rows in _sequence(seed):
        cols = [list(c) for c in zip(*rows)] if rows else [[], [], [], [], []]
        fast, a = update(fast, *cols[:4], t_s, P, cols[4])
        ref, b = update(ref, *cols[:4], t_s, P, cols[4], small=False)
        assert a.track_id.tolist() == b.track_id.tolist()
        np.testing.assert_allclose(a.range_rate_mps, b.range_rate_mps, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(a.bearing_rate_radps, b.bearing_rate_radps, rtol=1e-9, atol=1e-12)
        assert fast.ids.tolist() == ref.ids.tolist() and fast.next_id == ref.next_id
        assert fast.hidden.tolist() == ref.hidden.tolist() and fast.updates.tolist() == ref.updates.tolist()
        np.testing.assert_allclose(fast.s, ref.s, rtol=1e-9, atol=1e-12)
    assert any(taken)  # the float path ran (and gave way where gates overlap)


def test_overlapping_gates_go_to_the_numpy_path():
    state = empty_state()
    for _ in range(3):  # two established tracks 0.1 rad apart
        state, _ = update(state, [1.0, 1.0], [0.0, 0.1], [0.01, 0.01], [0.002, 0.002], None, P)
    # one reading halfway, inside both tracks' outlier gates: the assignment must choose
    args = (state.ids, state.s, state.hidden, state.updates, state.next_id, [1.0], [0.05], [0.01], [0.002],
            1 / 30, P, None)
    assert identity_small.update_small(*args) is None
    assert identity_small.update_small(*args[:5], [1.0, 1.0], [0.0, 0.1], [0.01] * 2, [0.002] * 2,
                                       1 / 30, P, None) is not None
