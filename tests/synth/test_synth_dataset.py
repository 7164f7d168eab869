"""Datasets on disk and in memory, and the ``rangebearing synth`` command."""

from __future__ import annotations

import argparse

import cv2
import numpy as np
import pytest

from rangebearing.cli import synth_cmd
from rangebearing.cli.main import main
from rangebearing.config import load_config
from rangebearing.core.types import CameraIntrinsics
from rangebearing.errors import SceneError
from rangebearing.evaluation.truth import TruthRow, read_truth, write_truth
from rangebearing.synth import LandmarkPose, Scene, generate, scene_truth, write_dataset


def test_write_dataset_matches_generate(tmp_path):
    rows = write_dataset(tmp_path, 6, seed=2, preset="multi")
    files = sorted(p.name for p in tmp_path.iterdir())
    assert files == [f"{i:06d}.png" for i in range(6)] + ["camera.yaml", "truth.csv"]
    truth = read_truth(tmp_path / "truth.csv")
    assert sum(len(v) for v in truth.values()) == len(rows) >= 12
    for name, image, frame_rows in generate(6, seed=2, preset="multi"):
        on_disk = cv2.imread(str(tmp_path / name))
        assert np.array_equal(on_disk, image)
        got = [v for r in truth[name] for v in (r.range_m, r.bearing_rad)]
        want = [v for r in frame_rows for v in (r.range_m, r.bearing_rad)]
        assert got == pytest.approx(want, abs=1e-6)


def test_jpeg_frames_are_what_generate_returns(tmp_path):
    write_dataset(tmp_path, 2, seed=1, fmt="jpg", jpeg_quality=70)
    for name, image, _ in generate(2, seed=1, fmt="jpg", jpeg_quality=70):
        assert name.endswith(".jpg")
        assert np.array_equal(cv2.imread(str(tmp_path / name)), image)
    png = next(generate(1, seed=1))[1]
    jpg = next(generate(1, seed=1, fmt="jpg", jpeg_quality=70))[1]
    assert 0 < np.abs(png.astype(int) - jpg.astype(int)).mean() < 6


def test_frames_without_a_landmark_have_no_rows(tmp_path):
    rows = write_dataset(tmp_path, 12, seed=3, preset="clutter")
    truth = read_truth(tmp_path / "truth.csv")
    frames = {p.name for p in tmp_path.glob("*.png")}
    assert set(truth) < frames  # some frames hold nothing
    assert len(rows) == len(truth)


def test_seed_decides_everything():
    a = [img for _, img, _ in generate(3, seed=9, preset="wide")]
    b = [img for _, img, _ in generate(3, seed=9, preset="wide")]
    c = [img for _, img, _ in generate(3, seed=10, preset="wide")]
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    assert not any(np.array_equal(x, y) for x, y in zip(a, c))


def test_camera_yaml_loads_as_config(tmp_path):
    cam = CameraIntrinsics().scaled(320, 240)
    write_dataset(tmp_path, 1, seed=0, camera=cam)
    assert load_config(tmp_path / "camera.yaml").camera == cam


def test_refuses_stale_frames_unless_overwrite(tmp_path):
    write_dataset(tmp_path, 3, seed=0)
    with pytest.raises(FileExistsError):
        write_dataset(tmp_path, 1, seed=0)
    write_dataset(tmp_path, 1, seed=0, overwrite=True)
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["000000.png"]


@pytest.mark.parametrize("kwargs, word", [
    ({"frames": -1}, "frames"), ({"seed": -2}, "seed"), ({"preset": "nope"}, "preset"),
    ({"fmt": "gif"}, "format"), ({"jpeg_quality": 0}, "jpeg_quality"),
])
def test_bad_arguments(tmp_path, kwargs, word):
    args = {"frames": 1, "seed": 0, **kwargs}
    with pytest.raises(SceneError, match=word):
        write_dataset(tmp_path, **args)
    assert not list(tmp_path.iterdir())


def test_scene_truth_lists_every_landmark_in_view_with_its_visible_fraction():
    # wholly in view; cut by the left frame edge (bearing 0.47 rad ~ 26.9 deg); behind the camera
    scene = Scene(landmarks=(LandmarkPose(0.5, 0.1), LandmarkPose(0.5, 0.47), LandmarkPose(0.5, 3.0)))
    rows = scene_truth(scene, "000001.png")
    assert [(r.frame, r.range_m, r.bearing_rad) for r in rows] == [("000001.png", 0.5, 0.1),
                                                                   ("000001.png", 0.5, 0.47)]
    whole, cut = rows
    assert (whole.visible, whole.red_visible, whole.blue_visible, whole.findable) == (1.0, 1.0, 1.0, True)
    assert 0.0 < cut.visible < 0.6 and not cut.findable
    assert cut.red_visible == pytest.approx(cut.blue_visible, abs=0.02)
    assert whole.robot is None


def test_truth_csv_round_trips_the_optional_columns(tmp_path):
    rows = [TruthRow("a.png", 0.5, 0.1, 0.5, 0.25, 0.75, False, 3), TruthRow("b.png", 1.0, -0.2)]
    write_truth(tmp_path / "t.csv", rows)
    header = (tmp_path / "t.csv").read_text().splitlines()[0]
    assert header == "frame,range_m,bearing_rad,visible,red_visible,blue_visible,findable,robot"
    back = read_truth(tmp_path / "t.csv")
    assert back["a.png"] == [rows[0]] and back["b.png"] == [rows[1]]
    # a plain three-column file still reads, optional fields unknown
    write_truth(tmp_path / "plain.csv", [TruthRow("c.png", 0.3, 0.0)])
    assert (tmp_path / "plain.csv").read_text().splitlines()[0] == "frame,range_m,bearing_rad"
    assert read_truth(tmp_path / "plain.csv")["c.png"][0].findable is None


# --- the command ---------------------------------------------------------------

def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="rangebearing")
    sub = p.add_subparsers(dest="command")
    synth_cmd.register(sub)
    return p


def test_command_writes_a_dataset_and_prints_one_line(tmp_path, capsys):
    out = tmp_path / "set"
    args = parser().parse_args(["synth", "--out", str(out), "--frames", "3", "--seed", "1",
                                "--preset", "wide", "--format", "jpg", "--jpeg-quality", "80",
                                "--size", "320x240", "--distortion=-0.2,0.05"])
    assert args.func(args) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 1 and "3 wide frames" in lines[0] and "320x240" in lines[0]
    assert cv2.imread(str(out / "000002.jpg")).shape == (240, 320, 3)
    cam = load_config(out / "camera.yaml").camera
    assert cam.distortion == (-0.2, 0.05, 0.0, 0.0, 0.0) and cam.width_px == 320
    assert len(read_truth(out / "truth.csv")) == 3


def test_command_refuses_a_used_folder(tmp_path, capsys):
    argv = ["synth", "--out", str(tmp_path), "--frames", "1", "--seed", "1"]
    assert main(argv) == 0
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.startswith("rangebearing: error: ") and "--overwrite" in err and "Traceback" not in err
    assert main([*argv, "--overwrite"]) == 0


@pytest.mark.parametrize("bad", [
    ["--size", "640by480"], ["--size", "8x8"], ["--distortion=0.1"], ["--distortion=a,b"],
    ["--jpeg-quality", "101"], ["--frames", "-3"], ["--preset", "nope"], ["--format", "bmp"],
])
def test_command_rejects_bad_options(tmp_path, bad, capsys):
    argv = ["synth", "--out", str(tmp_path), "--frames", "1", "--seed", "0"]
    with pytest.raises(SystemExit) as exc:
        parser().parse_args(argv + bad)
    assert exc.value.code == 2
    assert "error" in capsys.readouterr().err


def test_command_requires_out_frames_and_seed(capsys):
    with pytest.raises(SystemExit):
        parser().parse_args(["synth", "--frames", "1", "--seed", "0"])
    assert "--out" in capsys.readouterr().err
