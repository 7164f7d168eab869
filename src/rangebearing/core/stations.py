"""Guided calibration: the stations a landmark is placed at, and whether a station's readings are usable.

Pure: plans are built from the camera's field of view or parsed from text;
the CLI asks for each station, reads frames and decides with :func:`check_station`.
"""

from __future__ import annotations

import csv
import io
import math
from typing import List, Sequence, Tuple

import numpy as np

from .._compat import frozen
from ..errors import CalibrationError

DEFAULT_RANGES_M = (0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.2, 1.4)
WIDE_AT_M = (0.3, 0.6, 1.0, 1.4)  # stations near the edges of the field of view
MID_AT_M = (0.45, 0.8, 1.2)  # stations half-way out


@frozen
class Station:
    """Where to put the landmark: range to its axis (m) and bearing (rad, + left)."""

    name: str
    range_m: float
    bearing_rad: float

    @property
    def ahead_m(self) -> float:
        return self.range_m * math.cos(self.bearing_rad)

    @property
    def left_m(self) -> float:
        return self.range_m * math.sin(self.bearing_rad)

    def instruction(self) -> str:
        """What the operator is asked to do, with tape-measure coordinates."""
        deg = math.degrees(self.bearing_rad)
        if abs(deg) < 0.05:
            where = "straight ahead"
        else:
            side = "left" if deg > 0 else "right"
            where = f"{abs(deg):.0f}° to the {side} ({self.ahead_m:.3f} m ahead, {abs(self.left_m):.3f} m {side})"
        return f"place a landmark {self.range_m:.2f} m {where}"


@frozen
class StationCheck:
    """Whether a station's frames are usable, the mean reading and why not."""

    ok: bool
    reason: str
    found: int
    range_m: float
    bearing_rad: float


def default_plan(hfov_rad: float) -> Tuple[Station, ...]:
    """Stations over 0.2–1.4 m: one straight ahead at each range, and left/right ones across the field of view.

    The wide stations sit at 75 % of the half field of view, the middle ones at
    40 %, rounded to whole degrees so they are easy to lay out.
    """
    half = hfov_rad / 2.0
    out: List[Station] = []
    for r in DEFAULT_RANGES_M:
        bearings = [0.0]
        for share, at in ((0.75, WIDE_AT_M), (0.4, MID_AT_M)):
            if r in at:
                b = math.radians(round(math.degrees(share * half)))
                bearings = [b, *bearings, -b]
        for b in bearings:
            out.append(Station(f"s{len(out) + 1:02d}", r, b))
    return tuple(out)


def parse_plan(text: str, source: str = "<plan>") -> Tuple[Station, ...]:
    """Stations from CSV text: header ``range_m,bearing_deg`` (+ left), optional ``name`` column.

    Raises
    ------
    CalibrationError
        A missing column, a value that is not a number, a range not above 0 or
        a bearing beyond ±80°; the message gives the line.
    """
    reader = csv.DictReader(io.StringIO(text))
    header = [h.strip() for h in reader.fieldnames or []]
    missing = [c for c in ("range_m", "bearing_deg") if c not in header]
    if missing:
        raise CalibrationError(f"{source}:1: missing column(s) {', '.join(missing)}; expected range_m,bearing_deg")
    reader.fieldnames = header
    out: List[Station] = []
    for rec in reader:
        where = f"{source}:{reader.line_num}"
        try:
            r, b = float(rec["range_m"]), float(rec["bearing_deg"])
        except (TypeError, ValueError):
            raise CalibrationError(f"{where}: range_m and bearing_deg must be numbers") from None
        if not (math.isfinite(r) and r > 0):
            raise CalibrationError(f"{where}: range_m {r} must be above 0")
        if not (math.isfinite(b) and abs(b) <= 80):
            raise CalibrationError(f"{where}: bearing_deg {b} must lie within ±80")
        name = (rec.get("name") or "").strip() or f"s{len(out) + 1:02d}"
        out.append(Station(name, r, math.radians(b)))
    if not out:
        raise CalibrationError(f"{source}: no stations")
    return tuple(out)


def check_station(
    station: Station,
    readings: Sequence[Sequence[Tuple[float, float]]],
    range_tol: float = 0.3,
    bearing_tol_rad: float = math.radians(6.0),
    steady_range: float = 0.01,
    steady_bearing_rad: float = math.radians(0.3),
) -> StationCheck:
    """Decide whether N frames of a station are usable.

    Parameters
    ----------
    station : Station
    readings : sequence over frames of sequences of (range_m, bearing_rad)
        Every landmark seen in each frame, with the current (uncalibrated) model.
    range_tol, bearing_tol_rad
        How far from the asked station the landmark may read before calibration
        (the model is not fitted yet, so these are loose).
    steady_range, steady_bearing_rad
        Largest standard deviation over the frames (relative range, bearing):
        above it the landmark or the camera moved, or the detection flickers.

    Returns
    -------
    StationCheck
        ``ok`` with an empty ``reason``, or not ok and the reason in words.
    """
    picked = []
    for frame in readings:
        near = [(abs(b - station.bearing_rad), r, b) for r, b in frame]
        if near:
            picked.append(min(near)[1:])
    n = len(readings)
    if len(picked) < n:
        return StationCheck(False, f"landmark found in {len(picked)} of {n} frames", len(picked), math.nan, math.nan)
    r = np.array([p[0] for p in picked])
    b = np.array([p[1] for p in picked])
    rm, bm = float(r.mean()), float(b.mean())
    if r.std() > steady_range * rm or b.std() > steady_bearing_rad:
        why = f"not steady: range varies by {100 * r.std() / rm:.1f} %, bearing by {math.degrees(b.std()):.2f}°"
        return StationCheck(False, why, n, rm, bm)
    if abs(rm - station.range_m) > range_tol * station.range_m or abs(bm - station.bearing_rad) > bearing_tol_rad:
        why = (f"the landmark reads {rm:.2f} m at {math.degrees(bm):+.1f}°, far from the station "
               f"({station.range_m:.2f} m at {math.degrees(station.bearing_rad):+.1f}°): is it where asked?")
        return StationCheck(False, why, n, rm, bm)
    return StationCheck(True, "", n, rm, bm)
