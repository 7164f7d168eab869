""":func:`.identity.update` for the common small frame, on Python floats instead of numpy calls.

A frame with a few tracks and a few readings whose gates do not overlap (every
gated track has one gated reading and each reading one track: neighbours apart
in the view) costs the numpy path about sixty calls of a few microseconds each
on arrays of one to ten rows, more on a cold cache than all of its arithmetic.
:func:`update_small` does the same arithmetic (:mod:`.kalman`'s prediction and
correction, :mod:`.association`'s gates, outlier mixture and twins) on floats,
and gives up (``None``) where the numpy path must choose between overlapping
gates, so the caller runs that path. Ids are the same, the filter's values
equal to rounding (the numpy path sums the prediction as a matrix product).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, List, Optional, Sequence, Tuple

import numpy as np

if TYPE_CHECKING:
    from .identity import IdentityParams

#: ``(ids, s, hidden, updates, next_id)`` of the new state and ``(track_id, range_rate, bearing_rate)`` per reading
Small = Tuple[Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int], Tuple[np.ndarray, np.ndarray, np.ndarray]]

MAX_SMALL = 12  # tracks and readings this path takes at most (beyond: the numpy path's calls are amortised)


def _predicted(s: List[list], dt: float, params: IdentityParams) -> None:
    """:func:`.kalman.predict` of packed tracks as nested lists ``[[value, rate, p00, p01, p11] × 2] × n``, in place."""
    g0, g1, g2 = dt**4 / 4.0, dt**3 / 2.0, dt * dt
    qr = params.range_accel_mps2**2
    for t in s:
        for c, ch in enumerate(t):
            x, v, p00, p01, p11 = ch
            ch[0] = x + dt * v
            if c == 0:
                q = qr
            else:
                q = (params.lateral_accel_mps2 / max(t[0][0], 0.05) + params.yaw_accel_radps2) ** 2
            ch[2] = p00 + 2.0 * dt * p01 + dt * dt * p11 + q * g0
            ch[3] = p01 + dt * p11 + q * g1
            ch[4] = p11 + q * g2


def _variance(rng: float, rs: float, bs: float, vis: float, params: IdentityParams) -> Tuple[float, float]:
    """:func:`.kalman.measurement_variance` of one reading."""
    vr = max(rs, params.min_range_sigma_frac * abs(rng)) ** 2
    vb = max(bs, params.min_bearing_sigma_rad) ** 2
    if vis < 1.0:
        hidden = (1.0 - min(max(vis, 0.0), 1.0)) ** 2
        vr += hidden * (params.outlier_range_frac * rng) ** 2
        vb += hidden * params.outlier_bearing_rad**2
    return vr, vb


def _corrected(t: list, z: Tuple[float, float], noise: Tuple[float, float]) -> None:
    """:func:`.kalman.correct` of one track (nested lists) with a reading, in place."""
    for ch, zc, nc in zip(t, z, noise):
        x, v, p00, p01, p11 = ch
        innov = zc - x
        den = p00 + nc
        k0, k1 = p00 / den, p01 / den
        ch[0] = x + k0 * innov
        ch[1] = v + k1 * innov
        ch[2] = p00 - k0 * p00
        ch[3] = p01 - k0 * p01
        ch[4] = p11 - k1 * p01


def update_small(
    ids_now: np.ndarray, s_now: np.ndarray, hidden_now: np.ndarray, updates_now: np.ndarray, next_id: int,
    range_m: Sequence[float], bearing_rad: Sequence[float], range_sigma_m: Sequence[float],
    bearing_sigma_rad: Sequence[float], dt: float, params: IdentityParams, visible: Optional[Sequence[float]],
) -> Optional[Small]:
    """:func:`.identity.update` of the state's arrays (``dt``: its time step) where no two gates overlap;
    ``None`` where they do (or beyond ``MAX_SMALL`` tracks or readings)."""
    m, n = len(range_m), s_now.shape[0]
    if n > MAX_SMALL or m > MAX_SMALL:
        return None
    s = s_now.tolist()
    if n:
        _predicted(s, dt, params)
    ids, hidden, updates = ids_now.tolist(), [h + 1 for h in hidden_now.tolist()], updates_now.tolist()
    z = [(float(a), float(b)) for a, b in zip(range_m, bearing_rad)]
    vis = [1.0] * m if visible is None else [float(v) for v in visible]
    r = [_variance(z[j][0], float(range_sigma_m[j]), float(bearing_sigma_rad[j]), vis[j], params) for j in range(m)]
    det_row = [-1] * m
    if m and n:
        out_r = [(max(r[j][0], (params.outlier_range_frac * z[j][0]) ** 2), max(r[j][1], params.outlier_bearing_rad**2))
                 for j in range(m)]
        w_in, w_out = math.log1p(-params.outlier_fraction), math.log(params.outlier_fraction)
        pairs = []  # (track, reading, outlier?) in the numpy path's row-major order
        for i, t in enumerate(s):
            established = updates[i] >= params.rate_after_updates
            (xr, _, pr, _, _), (xb, _, pb, _, _) = t
            for j, (zr, zb) in enumerate(z):
                # the outlier noise is the wider (out_r >= r): a pair outside its gate is gated under neither
                if (zb - xb) ** 2 / (pb + out_r[j][1]) + (zr - xr) ** 2 / (pr + out_r[j][0]) > params.gate_d2:
                    continue
                lik = []
                inside = []
                for nr, nb in (r[j], out_r[j]):
                    vr, vb = pr + nr, pb + nb
                    d2 = (zr - xr) ** 2 / vr + (zb - xb) ** 2 / vb
                    inside.append(d2 <= params.gate_d2)
                    lik.append(-0.5 * (d2 + math.log(vr * vb)))
                if inside[0] or (inside[1] and established):
                    pairs.append((i, j, w_out + lik[1] > w_in + lik[0]))
        if len(pairs) > 1 and (len({p[0] for p in pairs}) < len(pairs) or len({p[1] for p in pairs}) < len(pairs)):
            return None  # gates overlap: the numpy path chooses (association.assign_gated)
        for i, j, outlier in pairs:
            _corrected(s[i], z[j], out_r[j] if outlier and vis[j] < 1.0 else r[j])  # (association.associate)
            hidden[i] = 0
            updates[i] += 1
            det_row[j] = i
        if pairs and len(pairs) < m:
            _twins(det_row, z, [j for _, j, _ in pairs], params)
    for j in range(m):
        if det_row[j] < 0:  # a new track (identity._births)
            s.append([[z[j][0], 0.0, r[j][0], 0.0, params.range_rate_prior_mps**2],
                      [z[j][1], 0.0, r[j][1], 0.0, params.bearing_rate_prior_radps**2]])
            ids.append(next_id)
            next_id += 1
            hidden.append(0)
            updates.append(1)
            det_row[j] = len(s) - 1
    nan = math.nan
    grown = [updates[k] >= params.rate_after_updates for k in det_row]
    identified = (np.array([ids[k] for k in det_row], dtype=np.int64),
                  np.array([s[k][0][1] if g else nan for k, g in zip(det_row, grown)], dtype=float),
                  np.array([s[k][1][1] if g else nan for k, g in zip(det_row, grown)], dtype=float))
    if hidden and max(hidden) > min(params.max_hidden_frames, params.max_hidden_young_frames):
        keep = [h <= (params.max_hidden_frames if u >= 2 else params.max_hidden_young_frames)
                for h, u in zip(hidden, updates)]
        ids, s, hidden, updates = ([v for v, k in zip(a, keep) if k] for a in (ids, s, hidden, updates))
    arr = np.array(s, dtype=float).reshape(len(s), 2, 5)
    return (np.array(ids, dtype=np.int64), arr, np.array(hidden, dtype=np.int64), np.array(updates, dtype=np.int64),
            next_id), identified


def _twins(det_row: List[int], z: List[Tuple[float, float]], cols: List[int], params: IdentityParams) -> None:
    """:func:`.association.twins` on lists: a leftover reading on a matched one takes that one's track."""
    for j in range(len(z)):
        if det_row[j] >= 0:
            continue
        best, best_db = -1, math.inf
        for c in cols:
            rng = z[c][0]
            db = abs(z[j][1] - z[c][1])
            twin = db <= params.twin_width_m / rng and abs(z[j][0] - rng) <= params.outlier_range_frac * rng
            if twin and db < best_db:
                best, best_db = c, db
        if best >= 0:
            det_row[j] = det_row[best]
