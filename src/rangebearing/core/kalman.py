"""A constant-velocity Kalman filter on (range, range rate, bearing, bearing rate), for many tracks at once.

Range and bearing are measured independently and their process noises are
independent, so the 4×4 filter is exactly two 2×2 filters (channels
``RANGE`` and ``BEARING``), written out in closed form over arrays of tracks:
``x`` is ``(n, 2, 2)`` (channel × value, rate), ``p`` is ``(n, 2, 3)`` (per
channel the covariance entries var value, cov value-rate, var rate).
Pure functions: arrays in, arrays out.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Tuple

import numpy as np

if TYPE_CHECKING:
    from .identity import IdentityParams

RANGE, BEARING = 0, 1  # channels of the state and covariance arrays


def measurement_variance(
    range_m: np.ndarray, range_sigma_m: np.ndarray, bearing_sigma_rad: np.ndarray, visible: np.ndarray,
    params: IdentityParams,
) -> np.ndarray:
    """``(m, 2)`` variances of range and bearing readings, sigmas floored by ``params``.

    A partly seen landmark (``visible`` < 1: hidden in part, or split from a
    neighbour) is trusted less than its sigmas say: ``(1 - visible)`` times the
    outlier sigmas are added in quadrature, so one such reading cannot bend a
    track's rate.
    """
    r = np.empty((range_m.shape[0], 2))
    np.maximum(range_sigma_m, params.min_range_sigma_frac * np.abs(range_m), out=r[:, RANGE])
    np.maximum(bearing_sigma_rad, params.min_bearing_sigma_rad, out=r[:, BEARING])
    np.square(r, out=r)
    hidden = np.square(1.0 - np.clip(visible, 0.0, 1.0))
    r[:, RANGE] += hidden * np.square(params.outlier_range_frac * range_m)
    r[:, BEARING] += hidden * params.outlier_bearing_rad**2
    return r


def predict(x: np.ndarray, p: np.ndarray, dt_s: float, params: IdentityParams) -> Tuple[np.ndarray, np.ndarray]:
    """Constant-velocity prediction ``dt_s`` ahead (discrete white-noise acceleration).

    ``F = [[1, dt], [0, 1]]``, ``Q = a² [[dt⁴/4, dt³/2], [dt³/2, dt²]]`` per
    channel, with ``a`` the range acceleration or the bearing acceleration
    at the track's predicted range.
    """
    dt = float(dt_s)
    xn = x.copy()
    xn[:, :, 0] += dt * x[:, :, 1]
    q = np.empty(x.shape[:2])
    q[:, RANGE] = params.range_accel_mps2**2
    q[:, BEARING] = np.square(params.lateral_accel_mps2 / np.maximum(xn[:, RANGE, 0], 0.05) + params.yaw_accel_radps2)
    p01, p11 = p[:, :, 1], p[:, :, 2]
    dt_p11 = dt * p11
    pn = np.empty_like(p)
    pn[:, :, 0] = p[:, :, 0] + dt * (2.0 * p01 + dt_p11) + q * (dt**4 / 4.0)
    pn[:, :, 1] = p01 + dt_p11 + q * (dt**3 / 2.0)
    pn[:, :, 2] = p11 + q * (dt * dt)
    return xn, pn


# Bearings are never wrapped: a camera sees less than ±90°, so a difference of
# two bearings of one neighbour is far from ±π.


def distances(x: np.ndarray, p: np.ndarray, z: np.ndarray, r: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Squared Mahalanobis distances ``d²`` of ``m`` readings ``z`` (``(m, 2)``, variances ``r``)
    from ``n`` predicted tracks, and ``d² + ln det S`` (twice the negative log-likelihood
    but for a constant), both ``(n, m)``.

    The log-determinant makes a confident track win over a vague one (a newcomer,
    or one coasting unseen) at the same ``d²``: a vague track's gate is wide, so
    ``d²`` alone would hand it readings that belong to a neighbour it overlaps.
    """
    s = p[:, None, :, 0] + r[None, :, :]
    d2 = (np.square(z[None, :, :] - x[:, None, :, 0]) / s).sum(axis=2)
    return d2, d2 + np.log(s[:, :, RANGE] * s[:, :, BEARING])


def correct(x: np.ndarray, p: np.ndarray, z: np.ndarray, r: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Kalman update of matched tracks ``x, p`` (``(k, 2, ...)``) with readings ``z``, variances ``r``."""
    innov = z - x[:, :, 0]
    p00, p01 = p[:, :, 0], p[:, :, 1]
    s = p00 + r
    k0, k1 = p00 / s, p01 / s
    xn = x.copy()
    xn[:, :, 0] += k0 * innov
    xn[:, :, 1] += k1 * innov
    pn = np.empty_like(p)
    pn[:, :, 0] = p00 - k0 * p00
    pn[:, :, 1] = p01 - k0 * p01
    pn[:, :, 2] = p[:, :, 2] - k1 * p01
    return xn, pn
