"""Accuracy of readings against ground truth: matching and the report ``replay --truth`` prints."""

from __future__ import annotations

import math
from typing import Iterable, List, Optional, Sequence, Tuple

import numpy as np

from .._compat import frozen
from ..core.types import Landmark
from .truth import TruthRow

MATCH_GAP_RAD = math.radians(3.0)
MATCH_RANGE_FRAC = 0.5  # a detection more than 50 % off the true range is another landmark


@frozen
class Match:
    """A true landmark and the detection matched to it (``None`` when missed)."""

    frame: str
    truth: TruthRow
    found: Optional[Landmark]

    @property
    def range_err_pct(self) -> float:
        """|error| / truth in percent; NaN for a missed landmark."""
        if self.found is None:
            return math.nan
        return 100.0 * abs(self.found.range_m - self.truth.range_m) / self.truth.range_m

    @property
    def bearing_err_deg(self) -> float:
        """|error| in degrees; NaN for a missed landmark."""
        if self.found is None:
            return math.nan
        return math.degrees(abs(self.found.bearing_rad - self.truth.bearing_rad))


def match_frame(
    frame: str, found: Sequence[Landmark], truths: Sequence[TruthRow], gap_rad: float = MATCH_GAP_RAD
) -> Tuple[List[Match], List[Landmark]]:
    """Match detections to truth by bearing and range, closest pairs first, each used once.

    A pair must be within ``gap_rad`` in bearing and within :data:`MATCH_RANGE_FRAC` of
    the true range (two neighbours one behind the other share a bearing: range tells
    them apart). Returns the matches (one per true landmark, ``found=None`` when missed)
    and the detections left over, which are false landmarks.
    """
    pairs = sorted(
        (abs(f.bearing_rad - t.bearing_rad) / gap_rad + abs(f.range_m - t.range_m) / (MATCH_RANGE_FRAC * t.range_m),
         i, j)
        for i, f in enumerate(found)
        for j, t in enumerate(truths)
        if abs(f.bearing_rad - t.bearing_rad) <= gap_rad and abs(f.range_m - t.range_m) <= MATCH_RANGE_FRAC * t.range_m
    )
    used_f, by_truth = set(), {}
    for _gap, i, j in pairs:
        if i in used_f or j in by_truth:
            continue
        used_f.add(i)
        by_truth[j] = found[i]
    matches = [Match(frame, t, by_truth.get(j)) for j, t in enumerate(truths)]
    false = [f for i, f in enumerate(found) if i not in used_f]
    return matches, false


@frozen
class AccuracyReport:
    """Detection rate, false landmarks, error statistics and σ coverage over a set of frames.

    ``findable`` counts true landmarks the truth marks findable (both bands ≥ 60 %
    visible; all of them when the truth does not say) and ``found_findable`` those
    detected. ``range_cover``/``bearing_cover`` are the shares of detections with
    |error| ≤ 2σ (their own ``range_sigma_m``/``bearing_sigma_rad``); NaN without σ.
    ``visible_err_*``: the error of the reported ``visible`` against the truth's
    visible fraction of the silhouette.
    """

    frames: int
    truths: int
    detected: int
    false_landmarks: int
    range_err_pct_mean: float
    range_err_pct_p95: float
    bearing_err_deg_mean: float
    bearing_err_deg_p95: float
    findable: int = 0
    found_findable: int = 0
    empty_frames: int = 0
    false_on_empty: int = 0
    range_cover: float = math.nan
    bearing_cover: float = math.nan
    visible_err_mean: float = math.nan  # |visible − true visible| over hits whose truth says (NaN: none does)
    visible_err_p95: float = math.nan

    @property
    def detection_rate(self) -> float:
        return self.detected / self.truths if self.truths else 1.0

    @property
    def findable_rate(self) -> float:
        return self.found_findable / self.findable if self.findable else 1.0


def _cover(hits: Sequence[Match]) -> Tuple[float, float]:
    """Shares of hits with |error| ≤ 2σ in range and in bearing (NaN when no hit carries a σ)."""
    with_sigma = [m for m in hits if m.found is not None and m.found.range_sigma_m > 0]
    if not with_sigma:
        return math.nan, math.nan
    r = np.mean([abs(m.found.range_m - m.truth.range_m) <= 2 * m.found.range_sigma_m for m in with_sigma])
    b = np.mean([abs(m.found.bearing_rad - m.truth.bearing_rad) <= 2 * m.found.bearing_sigma_rad for m in with_sigma])
    return float(r), float(b)


def accuracy(
    frames: Iterable[Tuple[str, Sequence[Landmark], Sequence[TruthRow]]],
) -> Tuple[AccuracyReport, List[Match]]:
    """Evaluate ``(frame, detections, truths)`` triples; returns the report and every match."""
    matches: List[Match] = []
    n_frames = n_false = n_empty = n_false_empty = 0
    for name, found, truths in frames:
        n_frames += 1
        m, false = match_frame(name, found, truths)
        matches.extend(m)
        n_false += len(false)
        if not truths:
            n_empty += 1
            n_false_empty += len(false)
    hits = [m for m in matches if m.found is not None]
    findable = [m for m in matches if m.truth.findable is not False]
    r = np.array([m.range_err_pct for m in hits]) if hits else np.array([math.nan])
    b = np.array([m.bearing_err_deg for m in hits]) if hits else np.array([math.nan])
    r_cover, b_cover = _cover(hits)
    v = np.array([abs(m.found.visible - m.truth.visible) for m in hits if m.truth.visible is not None])
    report = AccuracyReport(
        frames=n_frames,
        truths=len(matches),
        detected=len(hits),
        false_landmarks=n_false,
        range_err_pct_mean=float(np.mean(r)),
        range_err_pct_p95=float(np.percentile(r, 95)),
        bearing_err_deg_mean=float(np.mean(b)),
        bearing_err_deg_p95=float(np.percentile(b, 95)),
        findable=len(findable),
        found_findable=sum(1 for m in findable if m.found is not None),
        empty_frames=n_empty,
        false_on_empty=n_false_empty,
        range_cover=r_cover,
        bearing_cover=b_cover,
        visible_err_mean=float(np.mean(v)) if v.size else math.nan,
        visible_err_p95=float(np.percentile(v, 95)) if v.size else math.nan,
    )
    return report, matches


def format_report(rep: AccuracyReport) -> str:
    """A short human-readable accuracy report."""
    return "\n".join(
        [
            f"frames            {rep.frames} ({rep.empty_frames} without a landmark)",
            f"landmarks (truth) {rep.truths} ({rep.findable} findable: both bands >= 60 % visible)",
            f"detected          {rep.detected} ({100.0 * rep.detection_rate:.1f} %)",
            f"findable found    {rep.found_findable} ({100.0 * rep.findable_rate:.1f} %)",
            f"false landmarks   {rep.false_landmarks} ({rep.false_on_empty} on frames without a landmark)",
            f"range error       mean {rep.range_err_pct_mean:.2f} %   p95 {rep.range_err_pct_p95:.2f} %",
            f"bearing error     mean {rep.bearing_err_deg_mean:.3f}°  p95 {rep.bearing_err_deg_p95:.3f}°",
            f"sigma coverage    |err| <= 2 sigma: range {100.0 * rep.range_cover:.1f} %   "
            f"bearing {100.0 * rep.bearing_cover:.1f} %",
            f"visible error     mean {rep.visible_err_mean:.3f}   p95 {rep.visible_err_p95:.3f}"
            if math.isfinite(rep.visible_err_mean)
            else "visible error     - (the truth gives no visible share)",
        ]
    )
