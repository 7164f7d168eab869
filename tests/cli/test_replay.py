"""Replay beyond image folders: video files, and frames from a camera with lens distortion."""

from __future__ import annotations

import dataclasses

import cv2
import pytest

from rangebearing import Pipeline, load_config
from rangebearing.cli.main import main
from rangebearing.core.types import CameraIntrinsics
from rangebearing.evaluation.match import accuracy
from rangebearing.evaluation.truth import TruthRow, write_truth
from rangebearing.synth import generate, write_dataset


def test_replay_reads_a_video_and_matches_truth_by_frame_index(tmp_path, capsys):
    video = tmp_path / "clip.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 15.0, (640, 480))
    if not writer.isOpened():
        pytest.skip("this OpenCV build cannot write MJPG .avi")
    rows = []
    for i, (_, img, truth) in enumerate(generate(10, 77, "paper")):
        writer.write(img)
        rows.extend(TruthRow(str(i), t.range_m, t.bearing_rad) for t in truth)
    writer.release()
    write_truth(tmp_path / "truth.csv", rows)
    out = tmp_path / "r.jsonl"
    assert main(["replay", str(video), "--truth", str(tmp_path / "truth.csv"), "--out", str(out), "-q"]) == 0
    report = capsys.readouterr().out
    assert "detected          10 (100.0 %)" in report
    assert out.read_text().splitlines()[3].startswith('{"frame":3,')  # video frames are 0-based indices


def test_lens_distortion_is_undone_before_the_model():
    distorted = CameraIntrinsics(distortion=(-0.25, 0.08, 0.0, 0.0, 0.0))
    frames = list(generate(30, 78, "paper", camera=distorted))
    with_coeffs = dataclasses.replace(load_config(None), camera=distorted)
    without = load_config(None)
    errors = {}
    for name, cfg in (("with", with_coeffs), ("without", without)):
        pipe = Pipeline(cfg.pipeline, track=False)
        report, _ = accuracy((n, pipe.process(img).landmarks, rows) for n, img, rows in frames)
        assert report.detection_rate == 1.0
        errors[name] = (report.range_err_pct_mean, report.bearing_err_deg_mean)
    assert errors["with"][0] < 0.6 and errors["with"][1] < 0.05
    assert errors["without"][1] > 4 * errors["with"][1]  # ignoring the lens costs bearing accuracy


def test_synth_writes_the_camera_it_rendered_with(tmp_path):
    write_dataset(tmp_path / "d", 2, 1, "paper", camera=CameraIntrinsics(distortion=(-0.2, 0.0, 0.0, 0.0, 0.0)))
    assert load_config(tmp_path / "d" / "camera.yaml").camera.distortion[0] == -0.2


def test_replay_skips_and_counts_a_frame_the_detector_fails_on(tmp_path, static_clip, monkeypatch, capsys):
    from rangebearing.cli.main import main
    from rangebearing.core.pipeline import Pipeline

    real, calls = Pipeline.process, []

    def broken_on_the_second(self, frame, t_s=None, search=None):
        calls.append(1)
        if len(calls) == 2:
            raise ValueError("operands could not be broadcast together")
        return real(self, frame, t_s=t_s, search=search)

    monkeypatch.setattr(Pipeline, "process", broken_on_the_second)
    out = tmp_path / "r.jsonl"
    assert main(["replay", str(static_clip), "-q", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "skipped: detector failed on this frame (ValueError at" in err and "1 frame(s) skipped" in err
    assert len(out.read_text().splitlines()) == len(calls) - 1
