"""Track identity: a stable id per neighbour, and its range and bearing rates.

Every track is a constant-velocity Kalman filter on ``[range, range_rate,
bearing, bearing_rate]`` (:mod:`rangebearing.core.kalman`: two independent
2×2 filters in closed form, run over all tracks at once), fed with each
reading's own ``range_sigma_m`` and ``bearing_sigma_rad``.

Each frame (:func:`update`):

1. predict every track to the frame time (white-noise acceleration model,
   acceleration standard deviations from :class:`IdentityParams`);
2. gate: squared Mahalanobis distance ``d²`` of each detection from each
   prediction, with the innovation covariance (prediction plus the reading's
   noise); pairs beyond ``gate_d2`` are never made;
3. assign globally (:func:`~rangebearing.core.association.associate`: the
   most gated pairs, then the least total ``d² + ln det S``; a Hungarian
   solver for overlapping gates), update the matched tracks, except with a
   reading of two landmarks merged in the image (it keeps its track alive
   but moves it not);
4. unmatched tracks coast; one unmatched for more than ``max_hidden_frames``
   frames in a row is dropped; each unmatched detection starts a track with
   the next id;
5. a track that was unseen and is taken by another robot coming into view
   gives its id back when its own robot shows again and fits it better
   (:mod:`.identity_reclaim`).

Ids come from a counter in :class:`IdentityState` that only grows, so an id is
never reused while the state lives. The state is a value: :func:`update`
returns a new one and never reads a clock.
"""

from __future__ import annotations

from typing import Optional, Sequence, Tuple

import numpy as np

from .._compat import frozen
from .association import associate, twins
from .identity_reclaim import MIN_GAP, Taken, reclaimed
from .identity_small import Small, update_small
from .kalman import BEARING, P00, P11, RANGE, RATE, VALUE, correct, held_at_edges, measurement_variance, predict


@frozen
class IdentityParams:
    """Association and filter settings; defaults suit Zumo-sized robots seen at 30 fps.

    ``range_accel_mps2`` bounds the relative acceleration along the line of
    sight; the bearing's acceleration is ``lateral_accel_mps2 / range`` plus
    ``yaw_accel_radps2`` (the observer turning). They are the standard
    deviations of a white-noise acceleration, half the acceleration bounds
    (Bar-Shalom's rule for this model: 0.5 to 1 times the largest
    acceleration; robots accelerate smoothly, so the lower end). The ``*_prior`` values are the
    rate uncertainty of a new track; the ``min_*`` floors keep a reading with a
    zero or tiny sigma from making the gate a point.
    """

    max_hidden_frames: int = 15
    # a glimpse (a track of a single reading) has no rate at all: after this many frames unseen its
    # gate covers most of the view and would take the next newcomer's reading
    max_hidden_young_frames: int = 5
    gate_d2: float = 16.0  # chi-square, 2 dof: a true pair falls outside once in ~3,000
    range_accel_mps2: float = 0.75  # half of a 1.5 m/s² bound
    lateral_accel_mps2: float = 0.75
    yaw_accel_radps2: float = 1.0  # half of a 2 rad/s² bound
    range_rate_prior_mps: float = 0.6
    bearing_rate_prior_radps: float = 2.0
    min_range_sigma_frac: float = 0.01  # of the range
    min_bearing_sigma_rad: float = 0.0015
    # a reading of a merged or partly hidden landmark can be off by far more than its sigma says:
    # such outliers (this fraction of readings) are modelled with these wider sigmas
    outlier_fraction: float = 0.05
    outlier_range_frac: float = 0.05  # of the range
    outlier_bearing_rad: float = 0.015
    # a young track (fewer than rate_after_updates readings) yields to an established one it competes with
    young_penalty: float = 10.0  # added to -2 ln(likelihood)
    twin_width_m: float = 0.035  # a leftover reading this close to a matched one is the same landmark
    nominal_dt_s: float = 1.0 / 30.0  # frame interval when the frames carry no time
    max_dt_s: float = 1.0  # a longer gap is predicted as this long (a paused source)
    rate_after_updates: int = 3  # rates are published from this many measurements on


DEFAULT_PARAMS = IdentityParams()


@frozen
class IdentityState:
    """Every live track, as arrays over tracks (``n`` rows), and the id counter.

    ``s`` is ``(n, 2, 5)``, the packed filter state of :mod:`~rangebearing.core.kalman`:
    per channel (range, bearing) the value and rate (metres, m/s, radians,
    rad/s) and the covariance entries (var value, cov value-rate, var rate);
    :attr:`x` and :attr:`p` are views of its two parts. ``hidden`` counts the
    frames since a track was last measured, ``updates`` its measurements.
    Treat the arrays as read-only.
    """

    ids: np.ndarray  # (n,) int64
    s: np.ndarray  # (n, 2, 5) float
    hidden: np.ndarray  # (n,) int64
    updates: np.ndarray  # (n,) int64
    next_id: int = 0
    t_s: Optional[float] = None  # time of the last frame, when the frames carry one
    pending: Tuple[Taken, ...] = ()  # hidden tracks taken lately, which their own robot may still claim back

    @property
    def size(self) -> int:
        return int(self.ids.shape[0])

    @property
    def x(self) -> np.ndarray:
        """``(n, 2, 2)``: channel × (value, rate)."""
        return self.s[:, :, VALUE:P00]

    @property
    def p(self) -> np.ndarray:
        """``(n, 2, 3)``: channel × (var value, cov value-rate, var rate)."""
        return self.s[:, :, P00:]


def empty_state(first_id: int = 0) -> IdentityState:
    """No tracks; the next new track gets ``first_id``."""
    z = np.zeros(0, dtype=np.int64)
    return IdentityState(z, np.zeros((0, 2, 5)), z, z, first_id, None)


@frozen
class Identified:
    """What :func:`update` says about each detection of the frame (arrays over detections)."""

    track_id: np.ndarray  # (m,) int64
    range_rate_mps: np.ndarray  # (m,) float, NaN while the track is too young
    bearing_rate_radps: np.ndarray


def _dt(state: IdentityState, t_s: Optional[float], params: IdentityParams) -> float:
    if t_s is None or state.t_s is None:
        return params.nominal_dt_s
    dt = t_s - state.t_s
    if not dt > 0.0:  # a repeated or out-of-order stamp: assume the nominal interval
        return params.nominal_dt_s
    return min(dt, params.max_dt_s)


def _births(state: IdentityState, z: np.ndarray, r: np.ndarray, params: IdentityParams) -> IdentityState:
    """New tracks for readings ``z`` (``(k, 2)``), ids from the counter on."""
    k = z.shape[0]
    s0 = np.zeros((k, 2, 5))
    s0[:, :, VALUE] = z
    s0[:, :, P00] = r
    s0[:, RANGE, P11] = params.range_rate_prior_mps**2
    s0[:, BEARING, P11] = params.bearing_rate_prior_radps**2
    n = np.zeros(k, dtype=np.int64)
    return IdentityState(state.next_id + np.arange(k, dtype=np.int64), s0, n, n + 1, state.next_id + k)


def _identified(ids: np.ndarray, s: np.ndarray, updates: np.ndarray, det_row: np.ndarray,
                params: IdentityParams) -> Identified:
    grown = updates[det_row] >= params.rate_after_updates
    rates = np.where(grown[:, None], s[det_row, :, RATE], np.nan)
    return Identified(track_id=ids[det_row], range_rate_mps=rates[:, RANGE], bearing_rate_radps=rates[:, BEARING])


def update(
    state: IdentityState,
    range_m: Sequence[float],
    bearing_rad: Sequence[float],
    range_sigma_m: Sequence[float],
    bearing_sigma_rad: Sequence[float],
    t_s: Optional[float] = None,
    params: Optional[IdentityParams] = None,
    visible: Optional[Sequence[float]] = None,
    small: bool = True,
    view_rad: Optional[Tuple[float, float]] = None,
) -> Tuple[IdentityState, Identified]:
    """Associate one frame's readings with the tracks; returns the new state and each reading's id and rates.

    Parameters
    ----------
    state : IdentityState
        The tracks after the previous frame (:func:`empty_state` at the start of a run).
    range_m, bearing_rad, range_sigma_m, bearing_sigma_rad : sequence of float
        The frame's raw readings and their one-sigma uncertainties (equal length ``m``).
    t_s : float, optional
        Frame time in seconds on any steady clock. Without it (or on the first
        frame, or when it does not advance) frames are taken to be
        ``params.nominal_dt_s`` apart.
    params : IdentityParams, optional
        Defaults to ``IdentityParams()``.
    visible : sequence of float, optional
        Fraction of each landmark seen (0-1); 1 when not given.
    small : bool
        Take :func:`.identity_small.update_small` (floats, not numpy calls) where it
        applies; ``False`` runs the numpy path always (its reference).
    view_rad : (float, float), optional
        Bearings of the view's right and left edges: a track predicted out of the view is held
        at its edge (:func:`.kalman.held_at_edges`), where it will come back into view.

    Returns
    -------
    state : IdentityState
    identified : Identified
        Per reading, in input order: its track id (>= 0) and the filtered
        range and bearing rates, NaN until the track has
        ``params.rate_after_updates`` measurements.

    Notes
    -----
    The cost is numpy call overhead (a few microseconds a call at these
    sizes), so the common cases take short cuts that give the same result:
    no tracks or no readings skip the association, and when no two gates
    overlap (every gated track has one gated reading and vice versa) the
    pairs are taken without computing the assignment cost; up to
    ``identity_small.MAX_SMALL`` tracks and readings that case runs on floats.
    """
    params = DEFAULT_PARAMS if params is None else params
    n = state.size
    dt = _dt(state, t_s, params)
    if view_rad is not None and n:
        held = held_at_edges(state.s, dt, view_rad, params.twin_width_m)
        state = state if held is state.s else IdentityState(state.ids, held, state.hidden, state.updates,
                                                             state.next_id, state.t_s, state.pending)
    (ids, s, hidden, updates, next_id), (tid, rr, br) = _associated(
        state, range_m, bearing_rad, range_sigma_m, bearing_sigma_rad, dt, params, visible, small)
    pending = state.pending
    if pending or (n and int(state.hidden.max()) >= MIN_GAP):  # a hidden track taken by the wrong robot
        pending, (ids, s, updates, tid, rr, br) = reclaimed(
            (state.ids, state.s, state.hidden, state.updates), state.next_id, pending, (ids, s, updates, tid, rr, br),
            (range_m, bearing_rad, range_sigma_m, bearing_sigma_rad), visible, dt, params)
    return (IdentityState(ids, s, hidden, updates, next_id, t_s, pending),
            Identified(track_id=tid, range_rate_mps=rr, bearing_rate_radps=br))


def _associated(
    state: IdentityState, range_m: Sequence[float], bearing_rad: Sequence[float], range_sigma_m: Sequence[float],
    bearing_sigma_rad: Sequence[float], dt: float, params: IdentityParams, visible: Optional[Sequence[float]],
    small: bool,
) -> Small:
    """:func:`update`'s association, filter and births (``dt``: the time step), as arrays."""
    m, n = len(range_m), state.size
    if small:  # a few tracks and readings, no two gates overlapping: the same arithmetic on floats
        done = update_small(state.ids, state.s, state.hidden, state.updates, state.next_id, range_m, bearing_rad,
                            range_sigma_m, bearing_sigma_rad, dt, params, visible)
        if done is not None:
            return done
    s = predict(state.s, dt, params) if n else state.s
    hidden = state.hidden + 1
    updates, ids, next_id = state.updates, state.ids, state.next_id
    det_row = np.full(m, -1, dtype=np.intp)
    if m:
        z = np.empty((m, 2))
        z[:, RANGE] = range_m
        z[:, BEARING] = bearing_rad
        r = measurement_variance(z[:, RANGE], np.asarray(range_sigma_m, float),
                                 np.asarray(bearing_sigma_rad, float),
                                 None if visible is None else np.asarray(visible, float), params)
    if m and n:
        seen = np.ones(m) if visible is None else np.asarray(visible, float)
        rows, cols, noise, trust = associate(s, state.updates, z, r, seen, params)
        if rows.size:
            if not trust.all():  # merged readings: the track is seen, but not moved
                rows_t, cols_t, noise = rows[trust], cols[trust], noise[trust]
            else:
                rows_t, cols_t = rows, cols
            s[rows_t] = correct(s[rows_t], z[cols_t], noise)
            hidden[rows] = 0
            updates = updates.copy()
            updates[rows] += 1
            det_row[cols] = rows
            if rows.size < m:
                twins(det_row, z, cols, params)
    if m and (det_row < 0).any():  # readings no track took: new tracks, appended after the old ones
        new = np.nonzero(det_row < 0)[0]
        born = _births(state, z[new], r[new], params)
        det_row[new] = n + np.arange(new.size)
        ids, next_id = np.concatenate([ids, born.ids]), born.next_id
        s = np.concatenate([s, born.s])
        hidden, updates = np.concatenate([hidden, born.hidden]), np.concatenate([updates, born.updates])
    identified = _identified(ids, s, updates, det_row, params)
    if hidden.size and hidden.max() > min(params.max_hidden_frames, params.max_hidden_young_frames):
        keep = hidden <= np.where(updates >= 2, params.max_hidden_frames, params.max_hidden_young_frames)
        if not keep.all():
            ids, s, hidden, updates = ids[keep], s[keep], hidden[keep], updates[keep]
    return (ids, s, hidden, updates, next_id), (identified.track_id, identified.range_rate_mps,
                                                 identified.bearing_rate_radps)
