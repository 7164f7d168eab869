"""`rangebearing run` with source picamera2 as a real process against the clean-room fake (no libcamera at all),
a missing camera, and a picamera2 that cannot be imported."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path
from typing import Dict, Tuple

import numpy as np

from rangebearing.net.client import Subscriber
from tests.conftest import STATIC_SCENE
from tests.daemon.test_e2e import check_truth, wait_reading
from tests.sources.camera_fakes import ALT

TIMEOUT_S = 60.0  # a loaded 2-core machine: what happened is asserted, not how fast


def run_env(tmp_path: Path, rig: Dict[str, object], *path: Path) -> Dict[str, str]:
    rig_file = tmp_path / "rig.json"
    rig_file.write_text(json.dumps(rig))
    pythonpath = os.pathsep.join([*map(str, path), os.environ.get("PYTHONPATH", "")])
    return {**os.environ, "PYTHONPATH": pythonpath, "PICAMERA2_ALT_RIG": str(rig_file)}


def start(tmp_path: Path, config: str, env: Dict[str, str]) -> subprocess.Popen:
    cfg = tmp_path / "config.yaml"
    cfg.write_text(config)
    return subprocess.Popen([sys.executable, "-m", "rangebearing.cli.main", "run", "--config", str(cfg)],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def three_true_readings_then_stop(proc: subprocess.Popen, sub: Subscriber) -> Tuple[int, str]:
    """Three readings of the static scene, each checked against its truth, then SIGTERM: ``(exit code, stderr)``."""
    try:
        for _ in range(3):
            check_truth(wait_reading(sub, "pi", timeout_s=TIMEOUT_S))
        proc.send_signal(signal.SIGTERM)
        code = proc.wait(timeout=TIMEOUT_S)
    finally:
        if proc.poll() is None:
            proc.kill()
        _, stderr = proc.communicate()
    return code, stderr


def test_the_daemon_publishes_true_readings_from_the_clean_room_camera(tmp_path: Path) -> None:
    from rangebearing.synth import render

    rgb = np.ascontiguousarray(render(STATIC_SCENE, np.random.default_rng(3))[:, :, ::-1])
    np.save(tmp_path / "scene.npy", rgb[None])
    env = run_env(tmp_path, {"scene": str(tmp_path / "scene.npy")}, ALT)
    with Subscriber(port=0, timeout_s=TIMEOUT_S) as sub:
        proc = start(tmp_path, f"""
source: {{kind: picamera2, fps: 30, timeout_s: 1.0}}
publish: {{robot_id: pi, unicast: ["127.0.0.1:{sub.port}"]}}
""", env)
        code, stderr = three_true_readings_then_stop(proc, sub)  # main RGB888 measured, lores YUV420 searched
    assert code == 0, stderr
    assert "Traceback" not in stderr and "lores stream" not in stderr  # the lores stream was used, not refused


def test_a_missing_camera_ends_the_run_with_status_1(tmp_path: Path) -> None:
    env = run_env(tmp_path, {"cameras": []}, ALT)
    proc = start(tmp_path, "source: {kind: picamera2, open_timeout_s: 1.0}\n", env)
    _, stderr = proc.communicate(timeout=TIMEOUT_S)
    assert proc.returncode == 1, stderr
    assert "no camera 0 (0 found)" in stderr and "Traceback" not in stderr


def test_no_picamera2_is_one_error_line_and_status_1_without_retrying(tmp_path: Path) -> None:
    broken = tmp_path / "site" / "picamera2"
    broken.mkdir(parents=True)  # a picamera2 whose import fails, whatever the machine has installed
    (broken / "__init__.py").write_text("raise ImportError(\"No module named 'libcamera'\")\n")
    env = run_env(tmp_path, {}, tmp_path / "site")
    proc = start(tmp_path, "source: {kind: picamera2, open_timeout_s: 80}\n", env)
    _, stderr = proc.communicate(timeout=TIMEOUT_S)  # 80 s of retries would time this out
    assert proc.returncode == 1, stderr
    errors = [line for line in stderr.splitlines() if " ERROR " in line or " WARNING " in line]
    assert len(errors) == 1, stderr
    assert "cannot import picamera2" in errors[0] and "--system-site-packages" in errors[0]
    assert "Traceback" not in stderr
