"""Which reading belongs to which track: gates, the outlier mixture, merged readings, twins.

The association step of :func:`rangebearing.core.identity.update`, on the
packed predicted states of :mod:`rangebearing.core.kalman`. Pure numpy.
"""

from __future__ import annotations

from functools import lru_cache
from typing import TYPE_CHECKING, Tuple

import numpy as np

from .assignment import assign_gated
from .kalman import BEARING, RANGE, VALUE, distances

if TYPE_CHECKING:
    from .identity import IdentityParams


@lru_cache(maxsize=8)
def _log_weights(outlier_fraction: float) -> np.ndarray:
    """``(2, 1, 1)`` log prior weights of a reading as its sigmas say and of an outlier (read-only)."""
    w = np.array([np.log1p(-outlier_fraction), np.log(outlier_fraction)]).reshape(2, 1, 1)
    w.flags.writeable = False
    return w


def associate(s: np.ndarray, updates: np.ndarray, z: np.ndarray, r: np.ndarray, seen: np.ndarray,
              params: IdentityParams) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Pair predicted tracks with a frame's readings.

    Parameters
    ----------
    s : numpy.ndarray
        ``(n, 2, 5)`` packed predicted tracks (:mod:`~rangebearing.core.kalman`).
    updates : numpy.ndarray
        ``(n,)`` readings each track has had (a young track takes no outliers).
    z, r : numpy.ndarray
        ``(m, 2)`` readings (range m, bearing rad) and their variances.
    seen : numpy.ndarray
        ``(m,)`` fraction of each landmark seen (0-1).
    params : IdentityParams

    Returns
    -------
    rows, cols : numpy.ndarray
        Matched track rows and reading columns (int, equal length ``k``).
    noise : numpy.ndarray
        ``(k, 2)`` variances each matched reading updates its track with: its
        own, or the outlier ones when it is more likely an outlier.
    trust : numpy.ndarray
        ``(k,)`` bool: False for a merged reading (see below), which keeps its
        track alive but must not move it.
    """
    noise = np.empty((2, *z.shape))  # (2, m, 2): as the sigmas say, and as an outlier
    noise[0] = r
    np.square(params.outlier_range_frac * z[:, RANGE], out=noise[1, :, RANGE])
    noise[1, :, BEARING] = params.outlier_bearing_rad**2
    np.maximum(r, noise[1], out=noise[1])
    d2, nll = distances(s, z, noise)  # (2, n, m) each
    loglik = _log_weights(params.outlier_fraction) - 0.5 * nll  # of the two kinds of reading
    inside = d2 <= params.gate_d2
    established = updates >= params.rate_after_updates  # only a track with a motion takes outliers
    gated = inside[0] | (inside[1] & established[:, None])
    rows, cols = np.nonzero(gated)
    k = rows.size
    if k > 1 and (len(set(rows.tolist())) < k or len(set(cols.tolist())) < k):  # gates overlap: choose
        cost = -2.0 * np.logaddexp(loglik[0], loglik[1]) + np.where(established, 0.0, params.young_penalty)[:, None]
        rows, cols = assign_gated(np.where(gated, cost, np.inf), np.inf)
    both = loglik[:, rows, cols]
    outlier = both[1] > both[0]
    trust = np.ones(rows.size, dtype=bool)
    if k > rows.size:  # some gated pairs were not made: a track may have lost its reading to a merge
        free = np.ones(s.shape[0], dtype=bool)
        free[rows] = False
        if free.any():
            # A reading between its track and a gated track left without a reading (in bearing, on opposite
            # sides of their predictions) that is an outlier to its track or not wholly seen: the two
            # landmarks merged in the image (read 5-14 % off in range, between them in bearing). It says
            # both are there, not where either is, so it moves neither: fed to one track, frame after frame,
            # it would drag that track onto the other robot.
            b = z[cols, BEARING]
            side = (b - s[rows, BEARING, VALUE])[None, :] * (b[None, :] - s[free, BEARING, VALUE][:, None])
            trust = ~(((side < 0) & gated[free][:, cols]).any(axis=0) & (outlier | (seen[cols] < 1.0)))
    # a reading seen whole far from its track is the robot manoeuvring (a sudden stop or turn the filter's
    # acceleration bound did not foresee), not a bad reading: it updates with its own noise, so the track
    # follows instead of falling behind, reading after reading, until it loses its robot
    return rows, cols, noise[(outlier & (seen[cols] < 1.0)).astype(np.intp), cols], trust


def twins(det_row: np.ndarray, z: np.ndarray, cols: np.ndarray, params: IdentityParams) -> None:
    """Give a leftover reading that lies on a matched one (within a landmark's width in bearing
    and ``outlier_range_frac`` in range: the same landmark, seen twice) that reading's track, in place.

    A landmark split in two by the detector is then one neighbour, not a newcomer.
    """
    left = np.nonzero(det_row < 0)[0]
    db = np.abs(z[left, None, BEARING] - z[None, cols, BEARING])
    rng = z[cols, RANGE][None, :]
    dr = np.abs(z[left, None, RANGE] - rng)
    twin = (db <= params.twin_width_m / rng) & (dr <= params.outlier_range_frac * rng)
    has = twin.any(axis=1)
    if has.any():
        nearest = np.argmin(np.where(twin, db, np.inf), axis=1)
        det_row[left[has]] = det_row[cols[nearest[has]]]
