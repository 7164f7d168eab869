"""The swarm view: state folded from readings and presence, and the text it renders."""

from __future__ import annotations

import io
from typing import List, Optional

from rangebearing.cli.swarm_cmd import CLEAR, watch
from rangebearing.net.protocol import Reading, RemoteLandmark
from rangebearing.net.swarm import SwarmState, render
from rangebearing.net.zenoh_client import PresenceEvent


def lm(range_m: float, bearing_rad: float) -> RemoteLandmark:
    return RemoteLandmark(range_m, bearing_rad, True, 40.0, 0.0, 0.0, (0.0, 0.0), (0.0, 1.0), 10.0)


def test_rows_show_nearest_neighbour_age_and_presence() -> None:
    state = SwarmState()
    state.on_presence("zumo2", True)
    state.on_reading(Reading("zumo1", 7, 100.0, (lm(0.9, 0.1), lm(0.4, -0.5236)), fps=14.96), now_s=10.0)
    state.on_reading(Reading("zumo3", 1, 100.0, ()), now_s=10.0)
    state.on_presence("zumo3", False)
    rows = {r.robot: r for r in state.rows(now_s=10.5)}
    assert rows["zumo1"].neighbours == 2 and rows["zumo1"].nearest_range_m == 0.4
    assert rows["zumo1"].age_s == 0.5 and rows["zumo1"].alive is None
    assert rows["zumo2"].seq is None and rows["zumo2"].alive is True
    lines = render(state.rows(now_s=10.5))
    assert lines[1].split()[:7] == ["zumo1", "alive", "2", "0.400", "m", "-30.0°", "15.0"]
    assert lines[2].split()[:3] == ["zumo2", "alive", "0"]
    assert lines[3].split()[1] == "gone"
    assert lines[-1] == "2 of 3 robots alive"
    assert render(state.rows(now_s=13.0))[1].split()[1] == "stale"  # silent for 3 s


class FakeSource:
    """Scripted readings and presence on a fake clock that recv() advances."""

    def __init__(self, clock: List[float]) -> None:
        self.clock = clock
        self.readings = [Reading("zumo1", i, float(i), (lm(0.5, 0.0),), fps=15.0) for i in range(3)]
        self.events = [PresenceEvent("zumo1", True, 0.0)]

    def recv_presence(self, timeout_s: Optional[float] = 0.0) -> Optional[PresenceEvent]:
        return self.events.pop(0) if self.events else None

    def recv(self, timeout_s: Optional[float] = None) -> Optional[Reading]:
        if self.readings:
            return self.readings.pop(0)
        self.clock[0] += timeout_s or 0.01
        return None


def test_piped_output_is_plain_stamped_lines() -> None:
    clock = [0.0]
    out = io.StringIO()
    assert watch(FakeSource(clock), out, interval_s=1.0, duration_s=2.5, clock=lambda: clock[0]) == 0
    text = out.getvalue()
    assert "\x1b" not in text
    lines = text.splitlines()
    assert lines[0].endswith("zumo1 joined")
    assert any(line.split()[1:4] == ["zumo1", "alive", "1"] for line in lines)
    assert sum(line.endswith("robot alive") for line in lines) >= 3  # drawn at 0, 1, 2 s and at the end


def test_a_terminal_is_redrawn_in_place() -> None:
    clock = [0.0]
    out = io.StringIO()
    watch(FakeSource(clock), out, interval_s=1.0, duration_s=1.5, live=True, clock=lambda: clock[0])
    frames = out.getvalue().split(CLEAR)[1:]
    assert len(frames) >= 2 and "joined" not in out.getvalue()
    assert frames[-1].splitlines()[1].split()[:3] == ["zumo1", "alive", "1"]
