"""``camera.model`` in a config file: presets resolved for the configured size and crop, explicit keys win."""

import pytest
import yaml

from rangebearing.config import dump_config, load_config
from rangebearing.errors import ConfigError


def load(tmp_path, data):
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(data))
    return load_config(path)


def test_preset_at_the_source_size(tmp_path):
    cam = load(tmp_path, {"camera": {"model": "pi-v2"}, "source": {"width_px": 640, "height_px": 480}}).camera
    assert cam.fx_px == pytest.approx(3.04 / 1.12e-3 * 640 / 3280)  # 529.6 px: the "530" is a v2
    assert (cam.width_px, cam.height_px, cam.cx_px) == (640, 480, 319.5)


def test_cropped_mode_and_explicit_override(tmp_path):
    cfg = load(tmp_path, {"camera": {"model": "pi-v2", "width_px": 640, "height_px": 480,
                                     "sensor_crop": [1000, 752, 1280, 960], "cy_px": 250.0}})
    assert cfg.camera.fx_px == pytest.approx(2714.2857 * 0.5, rel=1e-6)
    assert cfg.camera.cy_px == 250.0  # explicit keys override the preset
    again = yaml.safe_load(dump_config(cfg))["camera"]  # written configs hold the numbers
    assert "model" not in again and again["fx_px"] == pytest.approx(cfg.camera.fx_px)


def test_scaler_crop_as_the_camera_reports_it(tmp_path):
    cam = load(tmp_path, {"camera": {"model": "pi-v3", "width_px": 640, "height_px": 360,
                                     "scaler_crop": [0, 0, 4608, 2592]}}).camera
    assert cam.fx_px == pytest.approx(4.74 / 1.4e-3 * 640 / 4608)


def test_bad_preset_values_are_all_reported(tmp_path):
    with pytest.raises(ConfigError) as err:
        load(tmp_path, {"camera": {"model": "pi-v9", "scaler_crop": [1, 2, 3]}, "source": {"fps": -1}})
    text = str(err.value)
    assert "camera.model" in text and "pi-v2" in text and "camera.scaler_crop" in text and "source.fps" in text
    with pytest.raises(ConfigError, match="not inside"):
        load(tmp_path, {"camera": {"model": "pi-v2", "scaler_crop": [3000, 0, 1280, 960]}})
    with pytest.raises(ConfigError, match="need a camera"):
        load(tmp_path, {"camera": {"sensor_crop": [0, 0, 640, 480]}})
