"""The state of a swarm as a controller sees it: who is alive, what each robot sees (pure: no I/O).

Feed it readings and presence events with the local receive time; ask it for one
row per robot and render those as text. Clocks are passed in, so tests can step time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Dict, List, Optional

from .._compat import frozen
from .protocol import Reading

STALE_S = 2.0  # a robot whose last reading is older than this is shown as "stale"


@frozen
class RobotRow:
    """One robot's line in the swarm view.

    ``alive`` is its liveliness token (None when presence is unknown, e.g. over UDP);
    ``age_s`` is how long ago (local clock) its last reading arrived, None if none did.
    """

    robot: str
    alive: Optional[bool]
    age_s: Optional[float]
    seq: Optional[int]
    neighbours: int
    nearest_range_m: Optional[float]
    nearest_bearing_rad: Optional[float]
    fps: Optional[float]
    readings: int


@dataclass
class _Robot:
    alive: Optional[bool] = None
    last: Optional[Reading] = None
    last_rx_s: Optional[float] = None
    readings: int = 0


class SwarmState:
    """Readings and presence folded into the latest state per robot."""

    def __init__(self) -> None:
        self._robots: Dict[str, _Robot] = {}

    def on_reading(self, reading: Reading, now_s: float) -> None:
        robot = self._robots.setdefault(reading.robot, _Robot())
        robot.last = reading
        robot.last_rx_s = now_s
        robot.readings += 1

    def on_presence(self, robot_id: str, alive: bool) -> None:
        self._robots.setdefault(robot_id, _Robot()).alive = alive

    def rows(self, now_s: float) -> List[RobotRow]:
        """Every robot heard of, by id."""
        out = []
        for robot_id in sorted(self._robots):
            r = self._robots[robot_id]
            last = r.last
            nearest = min(last.landmarks, key=lambda lm: lm.range_m) if last and last.landmarks else None
            out.append(RobotRow(
                robot=robot_id,
                alive=r.alive,
                age_s=None if r.last_rx_s is None else max(0.0, now_s - r.last_rx_s),
                seq=None if last is None else last.seq,
                neighbours=0 if last is None else len(last.landmarks),
                nearest_range_m=None if nearest is None else nearest.range_m,
                nearest_bearing_rad=None if nearest is None else nearest.bearing_rad,
                fps=None if last is None else last.fps,
                readings=r.readings,
            ))
        return out


HEADER = f"{'robot':<14} {'state':<6} {'seen':>4} {'nearest':>9} {'bearing':>8} {'fps':>6} {'age':>7} {'seq':>8}"


def _state(row: RobotRow) -> str:
    if row.alive is False:
        return "gone"
    if row.age_s is None:
        return "alive" if row.alive else "?"
    if row.age_s > STALE_S:
        return "stale"
    return "alive" if row.alive or row.alive is None else "?"


def format_row(row: RobotRow) -> str:
    """One fixed-width line: id, state, neighbours seen, nearest range and bearing, fps, age, seq."""
    rng = "-" if row.nearest_range_m is None else f"{row.nearest_range_m:.3f} m"
    brg = "-" if row.nearest_bearing_rad is None else f"{math.degrees(row.nearest_bearing_rad):+.1f}°"
    fps = "-" if row.fps is None else f"{row.fps:.1f}"
    age = "-" if row.age_s is None else f"{row.age_s:.1f} s"
    seq = "-" if row.seq is None else str(row.seq)
    return f"{row.robot:<14} {_state(row):<6} {row.neighbours:>4} {rng:>9} {brg:>8} {fps:>6} {age:>7} {seq:>8}"


def render(rows: List[RobotRow]) -> List[str]:
    """The whole table: a header, one line per robot, a summary line."""
    alive = sum(1 for r in rows if _state(r) == "alive")
    lines = [HEADER] + [format_row(r) for r in rows]
    lines.append(f"{alive} of {len(rows)} robot{'' if len(rows) == 1 else 's'} alive")
    return lines
