"""Three robots and a controller, each its own process and (when root) its own network namespace.

Each daemon replays a recorded clip under its own robot id and publishes over
Zenoh to the controller, ``rangebearing swarm``, which must see all three join,
their readings, and one leave the moment it is killed. In namespaces joined by a
bridge (private 10.213.1.0/24 addresses that exist nowhere else) the traffic
really crosses interfaces; without root it falls back to loopback with distinct
endpoints. Multicast scouting is off either way: nothing leaves the machine.
"""

from __future__ import annotations

import queue
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Callable, Iterator, List, Optional

import pytest

from tests.conftest import STATIC_SCENE

from . import netns
from .zenoh_helpers import free_tcp_port

ROBOTS = ("zumo1", "zumo2", "zumo3")
CLI = [sys.executable, "-m", "rangebearing.cli.main"]


def daemon_config(clip: Path, robot: str, controller: str, own_address: str) -> str:
    return f"""
source: {{kind: recorded, path: "{clip}", fps: 10, loop: true}}
publish:
  robot_id: {robot}
  unicast: ["127.0.0.1:47800"]   # this host's own loopback: nobody listens, nothing leaves
  zenoh:
    enabled: true
    mode: peer
    connect: ["tcp/{controller}"]
    listen: ["tcp/{own_address}:0"]
    scouting_multicast: false
"""


class Lines:
    """A process's stdout, line by line, waited on with a deadline."""

    def __init__(self, proc: subprocess.Popen) -> None:
        self.seen: List[str] = []
        self._q: queue.Queue = queue.Queue()
        assert proc.stdout is not None
        threading.Thread(target=lambda: [self._q.put(line) for line in proc.stdout], daemon=True).start()

    def wait_for(self, test: Callable[[str], bool], what: str, timeout_s: float = 20.0, since: int = 0) -> str:
        """The first line from ``since`` on (already printed or still to come) that passes ``test``."""
        for line in self.seen[since:]:
            if test(line):
                return line
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            try:
                line = self._q.get(timeout=0.1).rstrip("\n")
            except queue.Empty:
                continue
            self.seen.append(line)
            if test(line):
                return line
        raise AssertionError(f"controller never printed {what}; it printed:\n" + "\n".join(self.seen[-40:]))


@pytest.fixture(params=["namespaces", "loopback"])
def network(request: pytest.FixtureRequest) -> Iterator[Optional[netns.PrivateNetwork]]:
    """Namespaces ctl, zumo1..3 on one bridge; or None: every process on loopback, distinct endpoints."""
    if request.param == "loopback":
        yield None
        return
    why_not = netns.available()
    if why_not is not None:
        pytest.skip(f"no network namespaces here ({why_not}); the loopback variant still runs")
    with netns.PrivateNetwork(["ctl", *ROBOTS]) as net:
        yield net


def test_controller_sees_three_robots_join_report_and_one_crash(
    static_clip: Path, tmp_path: Path, network: Optional[netns.PrivateNetwork]
) -> None:
    def host_cmd(host: str, argv: List[str]) -> List[str]:
        return argv if network is None else network.command(host, argv)

    def address(host: str) -> str:
        return "127.0.0.1" if network is None else network.addresses[host]

    controller = f"{address('ctl')}:{7447 if network else free_tcp_port()}"
    ctl = subprocess.Popen(host_cmd("ctl", [*CLI, "swarm", "--listen", f"tcp/{controller}", "--interval", "0.5"]),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    out = Lines(ctl)
    robots = {}
    try:
        out.wait_for(lambda line: line.endswith("robots alive") or "robot alive" in line, "its first table")
        for robot in ROBOTS:
            cfg = tmp_path / f"{robot}.yaml"
            cfg.write_text(daemon_config(static_clip, robot, controller, address(robot)))
            robots[robot] = subprocess.Popen(host_cmd(robot, [*CLI, "run", "--config", str(cfg)]),
                                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        for robot in ROBOTS:
            out.wait_for(lambda line, r=robot: line.endswith(f"{r} joined"), f"'{robot} joined'")
        nearest = min(lm.range_m for lm in STATIC_SCENE.landmarks)
        for robot in ROBOTS:  # each robot's row: alive, two neighbours seen, the nearest at its true range
            row = out.wait_for(lambda line, r=robot: line.split()[1:4] == [r, "alive", "2"], f"a row for {robot}")
            assert float(row.split()[4]) == pytest.approx(nearest, rel=0.03)
        out.wait_for(lambda line: line.endswith("3 of 3 robots alive"), "all three alive at once")

        crash = len(out.seen)
        robots["zumo2"].kill()  # a crash: its Zenoh session vanishes, the token with it
        out.wait_for(lambda line: line.endswith("zumo2 left"), "'zumo2 left'", timeout_s=10, since=crash)
        out.wait_for(lambda line: line.split()[1:3] == ["zumo2", "gone"], "zumo2 as gone", since=crash)
        out.wait_for(lambda line: line.endswith("2 of 3 robots alive"), "two left alive", since=crash)
    finally:
        for proc in robots.values():
            if proc.poll() is None:
                proc.send_signal(signal.SIGTERM)
        for proc in robots.values():
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
        ctl.send_signal(signal.SIGINT)
        try:
            ctl.wait(timeout=10)
        except subprocess.TimeoutExpired:
            ctl.kill()
    assert ctl.returncode == 0, ctl.stderr.read() if ctl.stderr else ""
    for robot in ("zumo1", "zumo3"):
        assert robots[robot].returncode == 0
        assert "Traceback" not in robots[robot].stderr.read()  # type: ignore[union-attr]
