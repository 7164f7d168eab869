"""`rangebearing run` as a real process: systemd notifications, unicast and multicast readings,
SIGHUP reloads (good and bad), and SIGTERM ending it promptly with exit status 0."""

from __future__ import annotations

import math
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rangebearing.net.client import Subscriber
from tests.conftest import STATIC_SCENE

GROUP = "239.255.47.81"


def config_text(clip: Path, robot: str, port: int, mport: int) -> str:
    return f"""
source: {{kind: recorded, path: "{clip}", fps: 30, loop: true}}
publish:
  robot_id: {robot}
  unicast: ["127.0.0.1:{port}"]
  multicast_group: {GROUP}
  multicast_port: {mport}
  multicast_interface: 127.0.0.1
daemon: {{status_interval_s: 0.5}}
"""


def wait_notify(sock: socket.socket, wanted: str, timeout_s: float = 20.0) -> list:
    """Collect notify messages until one contains ``wanted``."""
    got = []
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        sock.settimeout(max(0.01, deadline - time.monotonic()))
        try:
            msg = sock.recv(4096).decode()
        except socket.timeout:
            break
        got.append(msg)
        if wanted in msg.split("\n"):
            return got
    raise AssertionError(f"no {wanted!r} from the daemon; got {got}")


def wait_reading(sub: Subscriber, robot: str, timeout_s: float = 10.0):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        r = sub.recv(timeout_s=max(0.01, deadline - time.monotonic()))
        if r is not None and r.robot == robot:
            return r
    raise AssertionError(f"no reading from {robot!r} within {timeout_s} s")


def check_truth(reading) -> None:
    truth = sorted(STATIC_SCENE.landmarks, key=lambda lm: lm.range_m)
    assert len(reading.landmarks) == 2
    for got, want in zip(reading.landmarks, truth):
        assert got.range_m == pytest.approx(want.range_m, rel=0.02)
        assert got.bearing_rad == pytest.approx(want.bearing_rad, abs=math.radians(0.3))


def test_daemon_end_to_end(static_clip, tmp_path):
    notify = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    notify.bind(str(tmp_path / "notify.sock"))
    with (
        notify,
        Subscriber(port=0, timeout_s=10) as uni,
        Subscriber(port=0, group=GROUP, interface="127.0.0.1") as multi,
    ):
        cfg = tmp_path / "config.yaml"
        cfg.write_text(config_text(static_clip, "alpha", uni.port, multi.port))
        env = dict(os.environ, NOTIFY_SOCKET=str(tmp_path / "notify.sock"), WATCHDOG_USEC="400000")
        env.pop("WATCHDOG_PID", None)
        proc = subprocess.Popen(
            [sys.executable, "-m", "rangebearing.cli.main", "run", "--config", str(cfg)],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            wait_notify(notify, "READY=1")
            wait_notify(notify, "WATCHDOG=1", timeout_s=5)

            first = wait_reading(uni, "alpha")
            check_truth(first)
            check_truth(wait_reading(multi, "alpha"))

            cfg.write_text(config_text(static_clip, "beta", uni.port, multi.port))
            proc.send_signal(signal.SIGHUP)
            wait_notify(notify, "RELOADING=1", timeout_s=5)
            check_truth(wait_reading(uni, "beta"))  # the new config took effect without a restart

            cfg.write_text("publish: {unicast: [nonsense]}\ndetection: {median_ksize: 4}\n")
            proc.send_signal(signal.SIGHUP)
            wait_notify(notify, "RELOADING=1", timeout_s=5)
            wait_notify(notify, "READY=1", timeout_s=5)  # the reload is over: rejected
            assert proc.poll() is None  # a bad config on SIGHUP is rejected, not fatal
            assert wait_reading(uni, "beta").seq > first.seq

            t0 = time.monotonic()
            proc.send_signal(signal.SIGTERM)
            code = proc.wait(timeout=5)
            elapsed = time.monotonic() - t0
        finally:
            if proc.poll() is None:
                proc.kill()
            _, stderr = proc.communicate()
        assert code == 0, stderr
        assert elapsed < 2.0
        assert "reload rejected" in stderr and "publish.unicast" in stderr and "detection.median_ksize" in stderr
        assert "config reloaded" in stderr
        assert "Traceback" not in stderr
        wait_notify(notify, "STOPPING=1", timeout_s=2)
