"""``rangebearing tune`` against the fake Pi camera showing a rendered landmark under a colour cast."""

import math

import pytest
import yaml

from rangebearing.cli.main import main
from rangebearing.config import load_config
from rangebearing.core.pipeline import Pipeline
from rangebearing.core.types import CameraIntrinsics
from rangebearing.synth import LandmarkPose, Scene, render
from rangebearing.synth.scene import Lighting

CAM = CameraIntrinsics().scaled(320, 240)
WARM = Lighting(wb_gains=(1.0, 0.85, 0.55))  # a tungsten-lit lab the camera's AWB left warm


def scene(range_m, bearing_rad):
    return Scene(camera=CAM, landmarks=(LandmarkPose(range_m, bearing_rad),), lighting=WARM)


@pytest.fixture
def camera(fake_picamera2):
    rgb = render(scene(0.45, 0.05))[:, :, ::-1].copy()
    fake_picamera2.WORLD.producer = lambda seq, h, w: rgb
    return fake_picamera2.WORLD


@pytest.fixture
def bad_config(tmp_path):
    """Thresholds that miss this landmark: a narrow red, a purple 'blue', a high saturation floor."""
    path = tmp_path / "lab.yaml"
    path.write_text(yaml.safe_dump({
        "source": {"kind": "picamera2", "width_px": 320, "height_px": 240, "controls": {"Sharpness": 1.0}},
        "detection": {"red_hue": [[0, 3]], "blue_hue": [[124, 140]], "s_min": 200},
    }))
    return path


def test_tune_locks_exposure_and_white_balance_and_fits_thresholds(camera, bad_config, tmp_path, capsys):
    before = load_config(bad_config)
    probe = render(scene(0.8, -0.15))
    assert Pipeline(before.pipeline, track=False).process(probe).landmarks == ()  # the old thresholds miss it

    out = tmp_path / "tuned.yaml"
    assert main(["tune", "--config", str(bad_config), "--out", str(out), "--settle", "5", "--frames", "4"]) == 0
    text = capsys.readouterr().out
    assert "loosened" in text and "found in all 4 frames" in text

    # the camera was locked at what its AE/AWB reported, picamera2's controls.py way
    locks = [c for c in camera.set_controls_calls if "AeEnable" in c]
    assert locks == [{"AeEnable": False, "ExposureTime": camera.auto_exposure_us, "AnalogueGain": camera.auto_gain,
                      "AwbEnable": False, "ColourGains": camera.auto_colour_gains}]
    tuned = load_config(out)
    controls = dict(tuned.source.controls)
    assert controls["AeEnable"] is False and controls["AwbEnable"] is False
    assert controls["ColourGains"] == camera.auto_colour_gains and controls["Sharpness"] == 1.0
    assert tuned.detection.white_balance == "none"  # the camera's balance is fixed: no software one on top

    # the new thresholds find the landmark elsewhere in the same light, at the right place
    found = Pipeline(tuned.pipeline, track=False).process(probe).landmarks
    assert len(found) == 1
    assert found[0].range_m == pytest.approx(0.8, rel=0.03)
    assert found[0].bearing_rad == pytest.approx(-0.15, abs=math.radians(0.5))
    # and they are not just the loosest step of the search
    assert tuned.detection.s_min > 70


def test_tune_keeps_the_old_file_and_refuses_an_empty_view(fake_picamera2, bad_config, tmp_path, capsys):
    grey = render(Scene(camera=CAM))[:, :, ::-1].copy()
    fake_picamera2.WORLD.producer = lambda seq, h, w: grey
    out = tmp_path / "tuned.yaml"
    out.write_text("# the lab's hand-made config\n")
    assert main(["tune", "--config", str(bad_config), "--out", str(out), "--settle", "2", "--frames", "3"]) == 1
    assert "no landmark found" in capsys.readouterr().err
    assert out.read_text() == "# the lab's hand-made config\n"  # nothing written over it


def test_tune_on_recorded_frames_tunes_colours_only(tmp_path, bad_config, capsys):
    import cv2

    clip = tmp_path / "clip"
    clip.mkdir()
    for i in range(3):
        cv2.imwrite(str(clip / f"{i:06d}.png"), render(scene(0.45 + 0.01 * i, 0.05)))
    out = tmp_path / "tuned.yaml"
    assert main(["tune", "--config", str(bad_config), "--source", str(clip), "--out", str(out), "--frames", "3"]) == 0
    assert "no exposure controls" in capsys.readouterr().err
    tuned = load_config(out)
    assert "AeEnable" not in dict(tuned.source.controls)
    assert tuned.detection.white_balance == "grey_world"
    assert tuned.detection.blue_hue != load_config(bad_config).detection.blue_hue
