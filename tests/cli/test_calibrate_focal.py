"""``calibrate`` checks the focal length against the bearings (the issue's fx_px: 530 on a 634 px camera)."""

import pytest
import yaml

from rangebearing.cli.main import main
from rangebearing.config import load_config
from rangebearing.core.types import CameraIntrinsics
from rangebearing.synth.dataset import write_dataset

CAM = CameraIntrinsics().scaled(320, 240)  # fx 317 px: the default 634 px camera at half size


@pytest.fixture(scope="module")
def frames(tmp_path_factory):
    d = tmp_path_factory.mktemp("paper")
    write_dataset(d, 24, seed=5, preset="paper", camera=CAM)
    return d


def config(tmp_path, fx_px):
    path = tmp_path / f"fx{fx_px}.yaml"
    path.write_text(yaml.safe_dump({"camera": {"fx_px": fx_px, "fy_px": fx_px}}))
    return path


def calibrate(frames, cfg, out, *extra):
    return main(["calibrate", str(frames), "--truth", str(frames / "truth.csv"), "--config", str(cfg),
                 "--out", str(out), *extra])


def test_right_focal_length_passes_strict(frames, tmp_path, capsys):
    assert calibrate(frames, config(tmp_path, 634.0), tmp_path / "ok.yaml", "--strict") == 0
    assert "focal length agrees" in capsys.readouterr().out


def test_wrong_focal_length_warns_loudly_and_fails_strict(frames, tmp_path, capsys):
    wrong = config(tmp_path, 530.0)
    assert calibrate(frames, wrong, tmp_path / "a.yaml") == 0  # written, but warned
    err = capsys.readouterr().err
    assert "WARNING: the intrinsics look wrong" in err and "configured 265.0" in err
    assert calibrate(frames, wrong, tmp_path / "b.yaml", "--strict") == 3
    assert (tmp_path / "b.yaml").exists()
    assert "bearing check: the intrinsics look wrong" in (tmp_path / "b.yaml").read_text()


def test_fit_focal_recovers_the_focal_length(frames, tmp_path, capsys):
    out = tmp_path / "fixed.yaml"
    assert calibrate(frames, config(tmp_path, 530.0), out, "--fit-focal", "--strict") == 0
    cam = load_config(out).camera
    assert cam.fx_px == pytest.approx(634.0, rel=0.01)
    assert cam.fy_px == pytest.approx(634.0, rel=0.01)
    assert "bearing error mean 0.0" in capsys.readouterr().out  # < 0.1° after the refit
