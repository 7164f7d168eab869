"""Global assignment of detections to tracks: gating, then a small Hungarian solver.

Pure numpy, no state. Sizes are tiny (at most ``max_landmarks`` tracks and
detections, 16 by default), so the cost is dominated by numpy call overhead:
:func:`assign_gated` solves the common case, where every gated track has a
single gated detection and vice versa, without any search, and hands only the
ambiguous rows and columns (neighbours whose gates overlap, e.g. while two
robots cross) to :func:`hungarian`.
"""

from __future__ import annotations

from typing import Tuple

import numpy as np


def hungarian(cost: np.ndarray) -> np.ndarray:
    """Minimum-cost assignment of rows to columns (Kuhn–Munkres, shortest augmenting paths).

    Parameters
    ----------
    cost : numpy.ndarray
        ``(n, m)`` float array of finite costs; any sign.

    Returns
    -------
    numpy.ndarray
        ``(n,)`` int array: the column assigned to each row, ``-1`` for rows
        left over when ``n > m``. Exactly ``min(n, m)`` rows are assigned and
        the sum of their costs is the least possible.

    Notes
    -----
    The O(n²·m) potential-based formulation (row potentials ``u``, column
    potentials ``v``; reduced costs ``c[i, j] - u[i] - v[j]`` stay >= 0). The
    inner loop over columns is vectorised; the loops over rows and path steps
    run at most ``min(n, m)`` and ``m`` times.
    """
    c = np.asarray(cost, dtype=np.float64)
    n, m = c.shape
    if n == 0 or m == 0:
        return np.full(n, -1, dtype=np.intp)
    if n > m:
        cols_of_rows = hungarian(c.T)  # for each column of c, its row
        out = np.full(n, -1, dtype=np.intp)
        ok = cols_of_rows >= 0
        out[cols_of_rows[ok]] = np.nonzero(ok)[0]
        return out
    u = np.zeros(n + 1)
    v = np.zeros(m + 1)
    row_of = np.zeros(m + 1, dtype=np.intp)  # 1-based row holding column j; 0 = free; column 0 is the root
    way = np.zeros(m + 1, dtype=np.intp)
    for i in range(1, n + 1):
        row_of[0] = i
        j0 = 0
        minv = np.full(m + 1, np.inf)
        used = np.zeros(m + 1, dtype=bool)
        while True:
            used[j0] = True
            i0 = row_of[j0]
            free = ~used[1:]
            reduced = c[i0 - 1] - u[i0] - v[1:]
            better = free & (reduced < minv[1:])
            minv[1:][better] = reduced[better]
            way[1:][better] = j0
            candidates = np.where(free, minv[1:], np.inf)
            j1 = int(np.argmin(candidates)) + 1
            delta = candidates[j1 - 1]
            u[row_of[used]] += delta
            v[used] -= delta
            minv[1:][free] -= delta
            j0 = j1
            if row_of[j0] == 0:
                break
        while j0:  # flip the augmenting path
            j1 = way[j0]
            row_of[j0] = row_of[j1]
            j0 = j1
    out = np.full(n, -1, dtype=np.intp)
    assigned = np.nonzero(row_of[1:])[0]
    out[row_of[1:][assigned] - 1] = assigned
    return out


def assign_gated(cost: np.ndarray, gate: float) -> Tuple[np.ndarray, np.ndarray]:
    """Pairs (track, detection) with ``cost <= gate``: as many pairs as possible, then least total cost.

    Parameters
    ----------
    cost : numpy.ndarray
        ``(n_tracks, n_detections)`` float array (e.g. squared Mahalanobis
        distances, or a negative log-likelihood); NaN and infinity count as
        outside the gate.
    gate : float
        Pairs costing more are never made.

    Returns
    -------
    rows, cols : numpy.ndarray
        Matched track and detection indices (int arrays of equal length),
        each index used at most once.

    Notes
    -----
    Unambiguous pairs (the only gated entry of both their row and their
    column) are taken directly; this is the optimum for them, since no other
    pair competes. The rest goes to :func:`hungarian` with out-of-gate
    entries priced above the sum of every gated cost, so the solver first
    maximises the number of gated pairs and then minimises their total cost.
    """
    n, m = cost.shape
    inside = np.isfinite(cost) & (cost <= gate)  # NaN and infinity are outside
    if n == 0 or m == 0 or not inside.any():
        return np.empty(0, dtype=np.intp), np.empty(0, dtype=np.intp)
    per_row = inside.sum(axis=1)
    per_col = inside.sum(axis=0)
    sole = inside & (per_row == 1)[:, None] & (per_col == 1)[None, :]
    rows, cols = np.nonzero(sole)
    rest_r = np.nonzero(per_row - sole.sum(axis=1) > 0)[0]
    if rest_r.size == 0:
        return rows, cols
    rest_c = np.nonzero(per_col - sole.sum(axis=0) > 0)[0]
    sub = cost[np.ix_(rest_r, rest_c)]
    sub_in = inside[np.ix_(rest_r, rest_c)]
    gated = np.where(sub_in, sub, 0.0)
    big = 1.0 + 2.0 * np.abs(gated).sum()  # dearer than any set of gated pairs
    picked = hungarian(np.where(sub_in, gated, big))
    ok = picked >= 0
    ok[ok] = sub_in[np.nonzero(ok)[0], picked[ok]]
    r2, c2 = rest_r[ok], rest_c[picked[ok]]
    return np.concatenate([rows, r2]), np.concatenate([cols, c2])
