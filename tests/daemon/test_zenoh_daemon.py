"""`rangebearing run` publishing over Zenoh (peer mode, loopback) as well as UDP, with presence."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

from rangebearing.net.client import Subscriber
from rangebearing.net.zenoh_client import ZenohSubscriber
from tests.daemon.test_e2e import check_truth, wait_reading
from tests.net.zenoh_helpers import free_tcp_port, hub


def zenoh_config(clip: Path, robot: str, udp_port: int, zenoh_port: int) -> str:
    return f"""
source: {{kind: recorded, path: "{clip}", fps: 30, loop: true}}
publish:
  robot_id: {robot}
  unicast: ["127.0.0.1:{udp_port}"]
  zenoh:
    enabled: true
    mode: peer
    connect: ["tcp/127.0.0.1:{zenoh_port}"]
    listen: ["tcp/127.0.0.1:0"]
    scouting_multicast: false
"""


def wait_presence(sub: ZenohSubscriber, robot: str, alive: bool, timeout_s: float = 10.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        ev = sub.recv_presence(0.1)
        if ev is not None and ev.robot == robot and ev.alive == alive:
            return
    raise AssertionError(f"no presence event {robot} alive={alive}")


def test_daemon_publishes_over_zenoh_and_udp_with_presence(static_clip: Path, tmp_path: Path) -> None:
    port = free_tcp_port()
    cfg = tmp_path / "config.yaml"
    with ZenohSubscriber(settings=hub(port), timeout_s=10) as zsub, Subscriber(port=0, timeout_s=10) as usub:
        cfg.write_text(zenoh_config(static_clip, "zumo9", usub.port, port))
        proc = subprocess.Popen([sys.executable, "-m", "rangebearing.cli.main", "run", "--config", str(cfg)],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            wait_presence(zsub, "zumo9", alive=True)
            got = zsub.recv_datagram(10)
            assert got is not None
            reading, payload = got
            assert reading.robot == "zumo9" and payload == reading.to_bytes()  # the v1 datagram itself
            check_truth(reading)
            check_truth(wait_reading(usub, "zumo9"))  # UDP goes on beside Zenoh
            seqs = {zsub.recv(5).seq for _ in range(5)}  # type: ignore[union-attr]
            assert len(seqs) == 5

            proc.send_signal(signal.SIGHUP)  # same Zenoh settings: the same session and token
            t_end = time.monotonic() + 1.0  # ~1 s of readings across the reload
            heard = 0
            while time.monotonic() < t_end:
                heard += zsub.recv(1.0) is not None
            assert heard >= 10 and "zumo9" in zsub.alive
            assert zsub.recv_presence(0.0) is None  # presence did not flicker

            proc.send_signal(signal.SIGTERM)
            assert proc.wait(timeout=10) == 0
            wait_presence(zsub, "zumo9", alive=False)  # the token goes with the daemon
        finally:
            if proc.poll() is None:
                proc.kill()
            _, stderr = proc.communicate()
    assert "zenoh peer rangebearing/zumo9/readings" in stderr
    assert "config reloaded" in stderr and "Traceback" not in stderr
    assert zsub.dropped == 0


def test_a_killed_daemon_leaves_presence_at_once(static_clip: Path, tmp_path: Path) -> None:
    port = free_tcp_port()
    cfg = tmp_path / "config.yaml"
    with ZenohSubscriber(settings=hub(port), timeout_s=10) as zsub, Subscriber(port=0) as usub:
        cfg.write_text(zenoh_config(static_clip, "zumo8", usub.port, port))
        proc = subprocess.Popen([sys.executable, "-m", "rangebearing.cli.main", "run", "--config", str(cfg)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            wait_presence(zsub, "zumo8", alive=True)
            assert zsub.recv(10) is not None
            proc.kill()  # a crash: no goodbye, the session simply vanishes
            proc.wait(timeout=5)
            t0 = time.monotonic()
            wait_presence(zsub, "zumo8", alive=False)
            assert time.monotonic() - t0 < 5.0
        finally:
            if proc.poll() is None:
                proc.kill()
