"""A hidden track taken by the wrong robot: its id back to its own robot when that one shows again.

A track unseen for a few frames (behind a neighbour, beyond the view's edge)
takes the first reading inside its gate, and that gate has grown while it was
unseen. Another robot coming into view there (at the same edge, at another
range) can be that reading: the track moves onto it, and when its own robot
comes back a few frames later, that robot gets a new id. All landmarks look
alike; what tells the two apart is where each is against the track's
prediction, and that can only be judged once both have been seen.

So each taking of a track unseen for ``MIN_GAP`` frames or more is kept in mind
(:class:`Taken`) for as long as the track could still have come back (up to
``max_hidden_frames`` from its last sighting): the track's state before the
taking, predicted on frame by frame, and how far (``d²``) the taking reading lay
from it. When a reading that would start a new track fits that prediction
inside the gate and closer than the taking reading did, the taking was the
mistake: that reading gets the old id and the track's history, and the track
that took the id follows its robot on under the new id the reading would have
had. Ids stay unique and are never reused.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Optional, Sequence, Tuple

import numpy as np

from .._compat import frozen
from .identity_small import _corrected, _predicted, _variance

if TYPE_CHECKING:
    from .identity import IdentityParams

MIN_GAP = 2  # frames unseen before a taking is kept in mind (a track seen last frame is not in doubt)


@frozen
class Taken:
    """A track taken after a gap: its id, its state before (predicted to the last frame), how far the taking
    reading lay, the readings it had, and how many more frames it may be given back."""

    track_id: int
    s: Tuple[Tuple[float, ...], ...]  # packed (2, 5) state, as nested tuples
    d2: float
    updates: int
    left: int


def _d2(s: Sequence[Sequence[float]], z: Tuple[float, float], noise: Tuple[float, float]) -> float:
    (xr, _, pr, _, _), (xb, _, pb, _, _) = s
    return (z[0] - xr) ** 2 / (pr + noise[0]) + (z[1] - xb) ** 2 / (pb + noise[1])


def _ahead(s: Sequence[Sequence[float]], dt: float, params: IdentityParams) -> Tuple[Tuple[float, ...], ...]:
    out = [list(s[0]), list(s[1])]
    _predicted([out], dt, params)
    return tuple(map(tuple, out))


Arrays = Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def reclaimed(
    before: Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], first_new_id: int, pending: Tuple[Taken, ...],
    after: Arrays, readings: Tuple[Sequence[float], Sequence[float], Sequence[float], Sequence[float]],
    visible: Optional[Sequence[float]], dt: float, params: IdentityParams,
) -> Tuple[Tuple[Taken, ...], Arrays]:
    """This frame's reclaims and takings; returns what is kept in mind and the new state's and readings' arrays.

    ``before``: the tracks before this frame (``ids, s, hidden, updates``);
    ``first_new_id``: the id the first track born this frame got; ``pending``: what
    earlier frames kept in mind; ``after``: the new state's ``ids, s, updates`` and the
    readings' ``track_id, range_rate, bearing_rate`` (changed copies are returned
    where a reading is given an id back); ``readings``: range, bearing and their sigmas.
    """
    b_ids, b_s, b_hidden, b_updates = before
    ids, s, updates, track_id, rr, br = after
    rng, bearing, rs, bs = readings
    m = len(rng)
    z = [(float(rng[j]), float(bearing[j])) for j in range(m)]
    vis = [1.0] * m if visible is None else [float(v) for v in visible]
    noise = [_variance(z[j][0], float(rs[j]), float(bs[j]), vis[j], params) for j in range(m)]
    kept = [Taken(p.track_id, _ahead(p.s, dt, params), p.d2, p.updates, p.left - 1) for p in pending if p.left > 0]
    tid = track_id.tolist()
    for j, t in enumerate(tid):
        if t < first_new_id or not kept:
            continue
        d2, k = min((_d2(p.s, z[j], noise[j]), k) for k, p in enumerate(kept))
        p = kept.pop(k)
        if d2 > params.gate_d2 or d2 >= p.d2:  # not closer than the taking reading: that one was the robot
            kept.insert(k, p)
            continue
        if ids is after[0]:  # copies before the first change: the arrays may be the last state's
            ids, s, updates, rr, br = ids.copy(), s.copy(), updates.copy(), rr.copy(), br.copy()
        row = ids.tolist().index(t)
        state = [list(p.s[0]), list(p.s[1])]
        _corrected(state, z[j], noise[j])
        s[row] = state
        updates[row] = p.updates + 1
        taker = np.nonzero(ids == p.track_id)[0]
        ids[taker] = t  # the track that took the id follows its robot on under the new one
        ids[row] = p.track_id
        tid = [p.track_id if x == t else t if x == p.track_id else x for x in tid]
        grown = updates[row] >= params.rate_after_updates
        rr[j], br[j] = (state[0][1], state[1][1]) if grown else (math.nan, math.nan)
    seen = set(tid)
    for i, h, u, st in zip(b_ids.tolist(), b_hidden.tolist(), b_updates.tolist(), b_s.tolist()):
        if h >= MIN_GAP and u >= 2 and i in seen:  # taken after a gap: kept in mind
            ahead = _ahead(st, dt, params)
            j = tid.index(i)
            kept.append(Taken(i, ahead, _d2(ahead, z[j], noise[j]), u, params.max_hidden_frames - h - 1))
    if tid != track_id.tolist():
        track_id = np.array(tid, dtype=np.int64)
    return tuple(kept), (ids, s, updates, track_id, rr, br)
