"""`run --record`, `record --out FILE.mcap` and `replay FILE.mcap` as real processes."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path
from typing import Dict, List

import cv2
import numpy as np
import pytest

from rangebearing.cli.main import main
from rangebearing.net.client import Subscriber
from rangebearing.net.protocol import decode_reading, wire_time_ns
from rangebearing.recording import McapRecording
from rangebearing.sources.recorded import list_images
from tests.conftest import STATIC_SCENE

RUN = [sys.executable, "-m", "rangebearing.cli.main", "run"]


def run_config(clip: Path, port: int, loop: bool, fps: float = 30) -> str:
    return (f'source: {{kind: recorded, path: "{clip}", fps: {fps}, loop: {str(loop).lower()}}}\n'
            f'publish: {{robot_id: rec1, unicast: ["127.0.0.1:{port}"]}}\n')


def clip_images(clip: Path) -> List[np.ndarray]:
    return [cv2.imread(str(p), cv2.IMREAD_COLOR) for p in list_images(clip)]


def test_kill_9_mid_recording_still_replays_every_complete_chunk(static_clip: Path, tmp_path: Path) -> None:
    cfg, out = tmp_path / "c.yaml", tmp_path / "run.mcap"
    sent: Dict[int, bytes] = {}
    with Subscriber(port=0, timeout_s=10) as sub:
        cfg.write_text(run_config(static_clip, sub.port, loop=True))
        proc = subprocess.Popen([*RUN, "--config", str(cfg), "--record", str(out), "--record-format", "png"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            first = sub.recv_datagram(30)  # the daemon is up
            assert first is not None, "the daemon published nothing"
            sent[first[0].seq] = first[1]
            t_end = time.monotonic() + 2.5  # the writer finishes a chunk at least every second
            while time.monotonic() < t_end:
                got = sub.recv_datagram(5)
                assert got is not None, "the daemon published nothing"
                sent[got[0].seq] = got[1]
        finally:
            proc.kill()  # kill -9: no footer, no summary, a chunk cut anywhere
            proc.wait(timeout=5)
    rec = McapRecording(out)
    frames = list(rec.frames())
    assert rec.truncated
    assert len(frames) >= 5  # at least the first chunk (the writer finishes one every second)
    images = clip_images(static_clip)
    for f in frames:
        np.testing.assert_array_equal(f.image, images[f.index % len(images)])  # PNG: bit-exact
    readings = list(rec.readings())
    assert readings and all(m.data == sent[decode_reading(m.data).seq] for m in readings)  # what was sent
    assert [m.log_time_ns for m in readings] == [wire_time_ns(decode_reading(m.data).t) for m in readings]
    # replay takes the cut file as it takes a folder or a video
    done = subprocess.run([sys.executable, "-m", "rangebearing.cli.main", "replay", str(out)],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    lines = [line for line in done.stdout.splitlines() if line[:1].isdigit()]
    assert len(lines) == len(frames) and lines[0].startswith("0: ")


def test_replay_mcap_with_truth_keyed_by_timestamp(static_clip: Path, tmp_path: Path,
                                                   capsys: pytest.CaptureFixture) -> None:
    cfg, out = tmp_path / "c.yaml", tmp_path / "run.mcap"
    with Subscriber(port=0) as sub:
        cfg.write_text(run_config(static_clip, sub.port, loop=False, fps=0))  # every frame, none skipped
        done = subprocess.run([*RUN, "--config", str(cfg), "--record", str(out)], capture_output=True, text=True,
                              timeout=60)
    assert done.returncode == 0, done.stderr
    assert "recorded 12 frames and 12 readings" in done.stderr
    rec = McapRecording(out)
    times = [f.t_ns for f in rec.frames(decode=False)]
    assert len(times) == 12 and not rec.truncated
    truth = tmp_path / "truth.csv"
    rows = ["frame,range_m,bearing_rad"]
    for i, t_ns in enumerate(times):  # half by timestamp, half by position
        key = str(t_ns) if i % 2 else str(i)
        rows += [f"{key},{lm.range_m},{lm.bearing_rad}" for lm in STATIC_SCENE.landmarks]
    truth.write_text("\n".join(rows) + "\n")
    assert main(["replay", str(out), "--truth", str(truth), "-q"]) == 0
    report = capsys.readouterr().out
    assert "landmarks (truth) 24" in report and "detected          24 (100.0 %)" in report, report
    truth.write_text("frame,range_m,bearing_rad\n1234567890123456789,0.5,0.0\n")
    assert main(["replay", str(out), "--truth", str(truth), "-q"]) == 1
    assert "no frame of the recording has this timestamp" in capsys.readouterr().err


def test_record_out_mcap_with_readings(static_clip: Path, tmp_path: Path) -> None:
    out = tmp_path / "rec.mcap"
    assert main(["record", "--source", str(static_clip), "--fps", "0", "--out", str(out), "--frames", "5",
                 "--readings"]) == 0
    rec = McapRecording(out)
    frames = list(rec.frames())
    images = clip_images(static_clip)
    assert [f.index for f in frames] == list(range(5))
    for f in frames:
        np.testing.assert_array_equal(f.image, images[f.index])
    readings = [decode_reading(m.data) for m in rec.readings()]
    assert len(readings) == 5 and all(len(r.landmarks) == 2 for r in readings)
    assert [wire_time_ns(r.t) for r in readings] == [f.t_ns for f in frames]
    assert rec.calibration() is not None
