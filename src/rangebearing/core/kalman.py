"""A constant-velocity Kalman filter on (range, range rate, bearing, bearing rate), for many tracks at once.

Range and bearing are measured independently and their process noises are
independent, so the 4×4 filter is exactly two 2×2 filters (channels
``RANGE`` and ``BEARING``), written out in closed form over arrays of tracks.
A track is one ``(2, 5)`` block of a packed state ``s`` (``(n, 2, 5)``): per
channel its value and rate (``VALUE``, ``RATE``: metres, m/s, radians,
rad/s) and its covariance entries (``P00`` var value, ``P01`` cov value-rate,
``P11`` var rate). One array per frame instead of one per quantity keeps the
number of numpy calls, which is what the filter costs at these sizes, small.
Pure functions: arrays in, arrays out.
"""

from __future__ import annotations

from functools import lru_cache
from typing import TYPE_CHECKING, Optional, Tuple

import numpy as np

if TYPE_CHECKING:
    from .identity import IdentityParams

RANGE, BEARING = 0, 1  # channels of the state and covariance arrays
VALUE, RATE, P00, P01, P11 = range(5)  # a channel's entries in the packed state


def measurement_variance(
    range_m: np.ndarray, range_sigma_m: np.ndarray, bearing_sigma_rad: np.ndarray, visible: Optional[np.ndarray],
    params: IdentityParams,
) -> np.ndarray:
    """``(m, 2)`` variances of range and bearing readings, sigmas floored by ``params``.

    A partly seen landmark (``visible`` < 1: hidden in part, or split from a
    neighbour) is trusted less than its sigmas say: ``(1 - visible)`` times the
    outlier sigmas are added in quadrature, so one such reading cannot bend a
    track's rate. ``visible`` ``None`` means every landmark was seen whole.
    """
    r = np.empty((range_m.shape[0], 2))
    np.maximum(range_sigma_m, params.min_range_sigma_frac * np.abs(range_m), out=r[:, RANGE])
    np.maximum(bearing_sigma_rad, params.min_bearing_sigma_rad, out=r[:, BEARING])
    np.square(r, out=r)
    if visible is not None and not (visible >= 1.0).all():  # else the terms below are all zero
        hidden = np.square(1.0 - np.clip(visible, 0.0, 1.0))
        r[:, RANGE] += hidden * np.square(params.outlier_range_frac * range_m)
        r[:, BEARING] += hidden * params.outlier_bearing_rad**2
    return r


@lru_cache(maxsize=16)
def _transition(dt_s: float) -> Tuple[np.ndarray, np.ndarray]:
    """The linear part of the prediction as a ``(10, 10)`` matrix on a track's flattened block, and the
    ``(3,)`` factors ``(dt⁴/4, dt³/2, dt²)`` of the process noise added to ``(P00, P01, P11)`` (read-only)."""
    dt = dt_s
    f = np.zeros((10, 10))
    for c in (0, 5):  # per channel: x' = x + dt v, v' = v; P' = F P Fᵀ
        v, r, p00, p01, p11 = range(c, c + 5)
        f[v, v] = 1.0
        f[r, v] = dt
        f[r, r] = 1.0
        f[p00, p00] = 1.0
        f[p01, p00] = 2.0 * dt
        f[p11, p00] = dt * dt
        f[p01, p01] = 1.0
        f[p11, p01] = dt
        f[p11, p11] = 1.0
    g = np.array([dt**4 / 4.0, dt**3 / 2.0, dt * dt])
    f.flags.writeable = g.flags.writeable = False
    return f, g


def predict(s: np.ndarray, dt_s: float, params: IdentityParams) -> np.ndarray:
    """Constant-velocity prediction ``dt_s`` ahead (discrete white-noise acceleration) of packed tracks ``s``.

    ``F = [[1, dt], [0, 1]]``, ``Q = a² [[dt⁴/4, dt³/2], [dt³/2, dt²]]`` per
    channel, with ``a`` the range acceleration or the bearing acceleration
    at the track's predicted range.
    """
    f, g = _transition(float(dt_s))
    n = s.shape[0]
    sn = (s.reshape(n, 10) @ f).reshape(n, 2, 5)
    q = np.empty((n, 2, 1))
    q[:, RANGE] = params.range_accel_mps2**2
    q[:, BEARING, 0] = np.square(params.lateral_accel_mps2 / np.maximum(sn[:, RANGE, VALUE], 0.05)
                                 + params.yaw_accel_radps2)
    sn[:, :, P00:] += q * g
    return sn


# Bearings are never wrapped: a camera sees less than ±90°, so a difference of
# two bearings of one neighbour is far from ±π.


def distances(s: np.ndarray, z: np.ndarray, r: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Squared Mahalanobis distances ``d²`` of ``m`` readings ``z`` (``(m, 2)``) from ``n`` predicted
    tracks ``s``, and ``d² + ln det S`` (twice the negative log-likelihood but for a constant).

    ``r`` holds the readings' variances, ``(m, 2)``, or ``(k, m, 2)`` for ``k``
    noise models at once; both results are ``(n, m)``, or ``(k, n, m)``.

    The log-determinant makes a confident track win over a vague one (a newcomer,
    or one coasting unseen) at the same ``d²``: a vague track's gate is wide, so
    ``d²`` alone would hand it readings that belong to a neighbour it overlaps.
    """
    var = s[:, None, :, P00] + r[..., None, :, :]
    d2 = (np.square(z[None, :, :] - s[:, None, :, VALUE]) / var).sum(axis=-1)
    return d2, d2 + np.log(var[..., RANGE] * var[..., BEARING])


_GAIN_OF = np.array([0, 0, 1])  # P00 and P01 are corrected with the value's gain, P11 with the rate's
_COV_OF = np.array([P00, P01, P01])


def correct(s: np.ndarray, z: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Kalman update of matched packed tracks ``s`` (``(k, 2, 5)``) with readings ``z``, variances ``r``
    (``(k, 2)`` each): ``K = (P00, P01) / (P00 + r)``, ``x += K·innovation``, ``P -= K·P[0]``."""
    sn = s.copy()
    innov = z - s[:, :, VALUE]
    gain = s[:, :, P00:P11] / (s[:, :, P00] + r)[:, :, None]  # (k, 2, 2): value's and rate's gain
    sn[:, :, VALUE:P00] += gain * innov[:, :, None]
    sn[:, :, P00:] -= gain[:, :, _GAIN_OF] * s[:, :, _COV_OF]
    return sn


def held_at_edges(s: np.ndarray, dt_s: float, view_rad: Tuple[float, float], width_m: float) -> np.ndarray:
    """Tracks about to be predicted past the view's edge held at that edge (packed ``s``, before :func:`predict`).

    A landmark whose prediction leaves the view (bearing beyond ``view_rad`` =
    ``(right edge, left edge)``, radians, positive left) while moving outwards can no
    longer be seen, so nothing will correct the prediction: its constant velocity
    would carry it on outwards, while the robot beyond the edge may stop or turn
    back, and when it comes into view again it does so at that edge. Such a track is
    put at the edge with no bearing rate (value and rate uncorrelated), its bearing
    variance at least a landmark's width (``width_m`` at its range) squared: where,
    along the edge, it shows again. Its range and the rate's variance are kept.
    Returns ``s`` itself when no track is held, else a changed copy.
    """
    lo, hi = view_rad
    out = None
    for i, ((rng, _, _, _, _), (b, v, p00, _, _)) in enumerate(s.tolist()):
        nxt = b + dt_s * v
        if not ((nxt > hi and v > 0.0) or (nxt < lo and v < 0.0)):
            continue
        if out is None:
            out = s.copy()
        ch = out[i, BEARING]
        ch[VALUE], ch[RATE], ch[P01] = hi if v > 0.0 else lo, 0.0, 0.0
        ch[P00] = max(p00, (width_m / max(rng, 0.05)) ** 2)
    return s if out is None else out
