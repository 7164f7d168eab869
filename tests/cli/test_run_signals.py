"""``rangebearing run`` as systemd runs it, a real process and real signals: a SIGHUP while it
is still starting does not kill it, 100 SIGHUPs in 2 s never stop the readings, SIGTERM exits 0."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from rangebearing.net.client import Subscriber

CLIP = Path(__file__).resolve().parents[2] / "samples" / "clip"


def _wait_for_sighup_handler(pid: int) -> bool:
    """Wait until the process catches SIGHUP; whether OpenCV was already loaded by then."""
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        try:
            status = Path(f"/proc/{pid}/status").read_text()
            maps = Path(f"/proc/{pid}/maps").read_text()
        except OSError:
            break
        caught = int(next(line for line in status.splitlines() if line.startswith("SigCgt:")).split()[1], 16)
        if caught & (1 << (signal.SIGHUP - 1)):
            return "cv2" in maps
        time.sleep(0.002)
    raise AssertionError("the process never installed a SIGHUP handler")


def test_sighup_at_start_and_100_sighups_later_never_end_the_daemon(tmp_path: Path) -> None:
    with Subscriber(port=0, timeout_s=10.0) as sub:
        cfg = tmp_path / "c.yaml"
        cfg.write_text(f'source: {{kind: recorded, path: "{CLIP}", fps: 30, loop: true}}\n'
                       f'publish: {{robot_id: sig, unicast: ["127.0.0.1:{sub.port}"]}}\n')
        proc = subprocess.Popen([sys.executable, "-m", "rangebearing.cli.main", "run", "--config", str(cfg)],
                                stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONUNBUFFERED": "1"})
        try:
            cv2_loaded = _wait_for_sighup_handler(proc.pid)
            proc.send_signal(signal.SIGHUP)
            assert not cv2_loaded, "SIGHUP is only handled once OpenCV is loaded (~1.5 s on a Pi)"
            assert sub.recv() is not None, "no reading after an early SIGHUP"
            assert proc.poll() is None
            arrivals = []
            for _ in range(100):
                proc.send_signal(signal.SIGHUP)
                t_end = time.monotonic() + 0.02
                while time.monotonic() < t_end:
                    if sub.recv(timeout_s=max(0.0, t_end - time.monotonic())) is not None:
                        arrivals.append(time.monotonic())
            t_end = time.monotonic() + 0.5
            while time.monotonic() < t_end:
                if sub.recv(timeout_s=0.1) is not None:
                    arrivals.append(time.monotonic())
            assert proc.poll() is None
            proc.send_signal(signal.SIGTERM)
            _, err = proc.communicate(timeout=10)
        finally:
            if proc.poll() is None:
                proc.kill()
    gaps = [b - a for a, b in zip(arrivals, arrivals[1:])]
    print(f"\n100 SIGHUPs in 2 s: {len(arrivals)} readings, longest gap {max(gaps) * 1000:.0f} ms")
    assert proc.returncode == 0, err[-2000:]
    assert err.count("config reloaded") >= 2 and "Traceback" not in err
    assert max(gaps) < 1.0
