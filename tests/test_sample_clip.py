"""The bundled sample clip (the README demo) replays with the accuracy its truth promises."""

from __future__ import annotations

from pathlib import Path

from rangebearing import Pipeline, load_config
from rangebearing.cli.main import main
from rangebearing.evaluation.match import accuracy
from rangebearing.evaluation.truth import read_truth
from rangebearing.sources.recorded import iter_recorded

ROOT = Path(__file__).resolve().parents[1]
CLIP = ROOT / "samples" / "clip"


def test_sample_clip_with_default_config():
    truth = read_truth(CLIP / "truth.csv")
    pipe = Pipeline(load_config(None).pipeline, track=True)  # a real sequence: tracking on, as in the daemon
    report, _ = accuracy((name, pipe.process(img).landmarks, truth.get(name, [])) for name, img in iter_recorded(CLIP))
    assert report.frames == 24 and report.truths == 48
    assert report.detection_rate == 1.0 and report.false_landmarks == 0
    assert report.range_err_pct_mean < 1.0 and report.bearing_err_deg_mean < 0.1


def test_demo_config_points_at_the_clip_from_any_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    cfg = load_config(ROOT / "config" / "demo.yaml")
    assert Path(cfg.source.path) == CLIP


def test_readme_demo_command_runs_the_daemon_on_the_clip(capsys):
    assert main(["run", "--config", str(ROOT / "config" / "demo.yaml"), "--fps", "0", "--echo"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 24
    assert all("2 landmarks" in line for line in lines)
