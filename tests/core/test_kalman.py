"""The packed closed-form filter agrees with the textbook matrix Kalman filter, track by track."""

from __future__ import annotations

import numpy as np
import pytest

from rangebearing.core.identity import IdentityParams
from rangebearing.core.kalman import BEARING, P00, P01, P11, RANGE, RATE, VALUE, correct, distances, predict

P = IdentityParams()


def _tracks(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    s = np.empty((n, 2, 5))
    s[:, RANGE, VALUE] = rng.uniform(0.2, 2.0, n)
    s[:, BEARING, VALUE] = rng.uniform(-0.4, 0.4, n)
    s[:, :, RATE] = rng.normal(0.0, 0.3, (n, 2))
    s[:, :, P00] = rng.uniform(1e-5, 1e-2, (n, 2))
    s[:, :, P11] = rng.uniform(1e-3, 1.0, (n, 2))
    s[:, :, P01] = 0.5 * np.sqrt(s[:, :, P00] * s[:, :, P11]) * rng.uniform(-1, 1, (n, 2))
    return s


def _cov(block: np.ndarray) -> np.ndarray:
    return np.array([[block[P00], block[P01]], [block[P01], block[P11]]])


@pytest.mark.parametrize("dt", [1 / 30, 0.2, 1.0])
def test_predict_is_f_p_ft_plus_q(dt):
    s = _tracks(7, 1)
    got = predict(s, dt, P)
    f = np.array([[1.0, dt], [0.0, 1.0]])
    g = np.array([[dt**4 / 4, dt**3 / 2], [dt**3 / 2, dt**2]])
    for i in range(7):
        r_pred = s[i, RANGE, VALUE] + dt * s[i, RANGE, RATE]
        accel = {RANGE: P.range_accel_mps2, BEARING: P.lateral_accel_mps2 / r_pred + P.yaw_accel_radps2}
        for c in (RANGE, BEARING):
            x = f @ s[i, c, VALUE:P00]
            cov = f @ _cov(s[i, c]) @ f.T + accel[c] ** 2 * g
            np.testing.assert_allclose(got[i, c, VALUE:P00], x, rtol=1e-12)
            np.testing.assert_allclose(_cov(got[i, c]), cov, rtol=1e-12)


def test_correct_is_the_textbook_update_and_distances_the_mahalanobis_form():
    s, rng = _tracks(5, 2), np.random.default_rng(3)
    z = s[:, :, VALUE] + rng.normal(0, 0.01, (5, 2))
    r = rng.uniform(1e-6, 1e-4, (5, 2))
    got = correct(s, z, r)
    h = np.array([[1.0, 0.0]])
    for i in range(5):
        for c in (RANGE, BEARING):
            cov = _cov(s[i, c])
            k = cov @ h.T / (h @ cov @ h.T + r[i, c])
            want = s[i, c, VALUE:P00] + (k * (z[i, c] - s[i, c, VALUE]))[:, 0]
            np.testing.assert_allclose(got[i, c, VALUE:P00], want, rtol=1e-12)
            np.testing.assert_allclose(_cov(got[i, c]), (np.eye(2) - k @ h) @ cov, rtol=1e-9, atol=1e-18)
    d2, nll = distances(s, z, r)
    var = s[:, None, :, P00] + r[None]
    want = ((z[None] - s[:, None, :, VALUE]) ** 2 / var).sum(axis=2)
    np.testing.assert_allclose(d2, want, rtol=1e-12)
    np.testing.assert_allclose(nll, want + np.log(var.prod(axis=2)), rtol=1e-12)
    d2k, _ = distances(s, z, np.stack([r, 4 * r]))  # two noise models at once
    np.testing.assert_allclose(d2k[0], d2, rtol=1e-15)
    assert (d2k[1] < d2).all()
