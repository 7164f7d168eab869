"""Track-id quality against a truth with a ``robot`` identity column: id switches and returns.

Per frame, detections are matched one-to-one to the findable true landmarks
(both bands >= 60 % visible, or ``findable`` unknown) by a global assignment on
range and bearing error (:func:`match_identities`). Then, per true robot, in
frame order:

* an **id switch** is a matched frame whose ``track_id`` differs from the one
  the robot had the last time it was matched (the CLEAR-MOT IDSW count),
  unless more than ``max_gap`` frames passed since (a new id is then due);
* a **return** is a matched frame after 1 to ``max_gap`` frames in which the
  robot was not matched (hidden, missed, out of view); it **keeps** its id when
  the id is the one it had before the gap.

The acceptance of issue 8: at most 1 switch per 1,000 matched landmark-frames,
and every return within 15 frames keeps its id.
"""

from __future__ import annotations

import math
from typing import Dict, Iterable, List, Sequence, Tuple

import numpy as np

from .._compat import frozen
from ..core.assignment import assign_gated
from ..core.types import Landmark
from .truth import TruthRow

GAP_RAD = math.radians(2.0)  # farther is not a reading of this robot
GAP_RANGE_FRAC = 0.05  # beyond the p95 range error issue 8 allows (3 %): a merged reading, not this robot


def match_identities(found: Sequence[Landmark], truths: Sequence[TruthRow]) -> List[Tuple[TruthRow, Landmark]]:
    """Pairs (truth, detection) for the findable truths that have a ``robot`` id.

    Cost: squared bearing error in degrees plus squared range error in units
    of 5 % of the range; pairs more than 2° or 5 % apart are never made (a reading that far
    off, e.g. of two landmarks merged into one, is not a reading of this robot).
    A hidden robot straight behind a visible one is not findable, so it never
    takes the visible one's detection.
    """
    rows = [t for t in truths if t.robot is not None and t.findable is not False]
    if not rows or not found:
        return []
    tb = np.array([t.bearing_rad for t in rows])
    tr = np.array([t.range_m for t in rows])
    fb = np.array([f.bearing_rad for f in found])
    fr = np.array([f.range_m for f in found])
    db = np.abs(tb[:, None] - fb[None, :])
    dr = np.abs(tr[:, None] - fr[None, :]) / tr[:, None]
    cost = np.square(np.degrees(db)) + np.square(dr / 0.05)
    cost[(db > GAP_RAD) | (dr > GAP_RANGE_FRAC)] = np.inf
    r, c = assign_gated(cost, 1e6)  # every finite cost is inside the gates above
    return [(rows[i], found[j]) for i, j in zip(r.tolist(), c.tolist())]


@frozen
class IdReport:
    """Id switches and returns over a sequence."""

    frames: int
    landmark_frames: int  # matched (truth, detection) pairs
    robots: int
    switches: int
    untracked: int  # matched detections without an id (track_id < 0)
    returns: int  # matched again after 1..max_gap frames unmatched
    returns_kept: int
    max_gap: int
    rates: int = 0  # matched readings with published rates and a true rate to compare with
    range_rate_err_mps: Tuple[float, float] = (math.nan, math.nan)  # |error|: median, p90
    bearing_rate_err_radps: Tuple[float, float] = (math.nan, math.nan)

    @property
    def switches_per_1000(self) -> float:
        return 1000.0 * self.switches / self.landmark_frames if self.landmark_frames else 0.0

    @property
    def passed(self) -> bool:
        """Issue 8: <= 1 switch per 1,000 landmark-frames, every return keeps its id, all tracked."""
        return self.switches_per_1000 <= 1.0 and self.returns_kept == self.returns and self.untracked == 0


def _rate_errors(published: List[Tuple[int, int, float, float]], where: Dict[Tuple[int, int], Tuple[float, float]],
                 fps: float) -> Tuple[int, Tuple[float, float], Tuple[float, float]]:
    """|published - true| rates, the true ones by central difference of the truth (frames 1/fps apart)."""
    er, eb = [], []
    for robot, index, rr, br in published:
        a, b = where.get((robot, index - 1)), where.get((robot, index + 1))
        if a is not None and b is not None:
            er.append(abs(rr - (b[0] - a[0]) * fps / 2.0))
            eb.append(abs(br - (b[1] - a[1]) * fps / 2.0))
    if not er:
        return 0, (math.nan, math.nan), (math.nan, math.nan)
    return (len(er), (float(np.median(er)), float(np.percentile(er, 90))),
            (float(np.median(eb)), float(np.percentile(eb, 90))))


def id_report(frames: Iterable[Tuple[Sequence[Landmark], Sequence[TruthRow]]], max_gap: int = 15,
              fps: float = 30.0) -> IdReport:
    """Count id switches and returns over ``(detections, truths)`` per frame, in frame order (``fps``
    apart: the true rates the published ones are compared with come from the truth's positions)."""
    last: Dict[int, Tuple[int, int]] = {}  # robot -> (track id, frame index) when last matched
    where: Dict[Tuple[int, int], Tuple[float, float]] = {}  # (robot, frame index) -> true (range, bearing)
    published: List[Tuple[int, int, float, float]] = []
    n_frames = pairs = switches = untracked = returns = kept = 0
    for index, (found, truths) in enumerate(frames):
        n_frames += 1
        where.update(((int(t.robot), index), (t.range_m, t.bearing_rad)) for t in truths if t.robot is not None)
        for truth, lm in match_identities(found, truths):
            pairs += 1
            if lm.track_id < 0:
                untracked += 1
                continue
            robot = int(truth.robot)  # type: ignore[arg-type]
            if lm.range_rate_mps is not None and lm.bearing_rate_radps is not None:
                published.append((robot, index, lm.range_rate_mps, lm.bearing_rate_radps))
            if robot in last:
                before, seen = last[robot]
                gap = index - seen - 1
                if lm.track_id != before and gap <= max_gap:  # a new id after a longer absence is no switch
                    switches += 1
                if 1 <= gap <= max_gap:
                    returns += 1
                    kept += lm.track_id == before
            last[robot] = (lm.track_id, index)
    return IdReport(n_frames, pairs, len(last), switches, untracked, returns, kept, max_gap,
                    *_rate_errors(published, where, fps))


def format_id_report(rep: IdReport) -> str:
    """The lines ``replay --truth`` prints for track ids."""
    verdict = "meets" if rep.passed else "MISSES"
    return "\n".join([
        f"track ids         {rep.robots} robots, {rep.landmark_frames} landmark-frames matched",
        f"id switches       {rep.switches} ({rep.switches_per_1000:.2f} per 1,000 landmark-frames)",
        f"returns <= {rep.max_gap} fr   {rep.returns_kept} of {rep.returns} kept their id",
        *([f"untracked         {rep.untracked} matched landmarks without an id"] if rep.untracked else []),
        *([f"range rate error  median {rep.range_rate_err_mps[0]:.3f} m/s  p90 {rep.range_rate_err_mps[1]:.3f} m/s"
           f"  ({rep.rates} readings)",
           f"bearing rate err  median {math.degrees(rep.bearing_rate_err_radps[0]):.2f}°/s"
           f"  p90 {math.degrees(rep.bearing_rate_err_radps[1]):.2f}°/s"] if rep.rates else []),
        f"issue 8 ids       {verdict} the target (<= 1 switch per 1,000, every return keeps its id)",
    ])
