""":func:`.identity.update` for a frame's :class:`~rangebearing.core.types.Landmark` objects."""

from __future__ import annotations

import operator
from dataclasses import fields
from typing import Optional, Sequence, Tuple

import numpy as np

from .identity import DEFAULT_PARAMS, IdentityParams, IdentityState, update
from .types import Landmark

_MEASURED = operator.attrgetter("range_m", "bearing_rad", "range_sigma_m", "bearing_sigma_rad", "visible")
_FIELDS = tuple(f.name for f in fields(Landmark))
_ALL = operator.attrgetter(*_FIELDS)
_TRACK, _RANGE_RATE, _BEARING_RATE = (_FIELDS.index(k) for k in ("track_id", "range_rate_mps", "bearing_rate_radps"))


def identify(
    state: IdentityState, landmarks: Sequence[Landmark], t_s: Optional[float], params: IdentityParams = DEFAULT_PARAMS
) -> Tuple[IdentityState, Tuple[Landmark, ...]]:
    """:func:`update` for a frame's landmarks: the same landmarks, in the same order, with
    ``track_id``, ``range_rate_mps`` and ``bearing_rate_radps`` filled in.

    The measured fields (``range_m``, ``bearing_rad``, the sigmas, …) are
    copied unchanged: the filter only adds rates.
    """
    if landmarks:
        cols = np.array([_MEASURED(lm) for lm in landmarks], dtype=float).T
        state, out = update(state, cols[0], cols[1], cols[2], cols[3], t_s, params, cols[4])
    else:
        state, out = update(state, (), (), (), (), t_s, params)
    labelled = []
    for lm, tid, rr, br in zip(landmarks, out.track_id.tolist(), out.range_rate_mps.tolist(),
                               out.bearing_rate_radps.tolist()):
        values = list(_ALL(lm))  # a copy with three fields changed, without dataclasses.replace's cost
        values[_TRACK] = tid
        values[_RANGE_RATE] = None if rr != rr else rr  # NaN (no history yet) -> None
        values[_BEARING_RATE] = None if br != br else br
        labelled.append(Landmark(*values))
    return state, tuple(labelled)
