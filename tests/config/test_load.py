import subprocess
import sys
from pathlib import Path

import pytest

from rangebearing.config import Config, config_from_mapping, dump_config, load_config
from rangebearing.errors import ConfigError

ROOT = Path(__file__).resolve().parents[2]


def test_defaults_without_a_file():
    cfg = load_config(None)
    assert cfg == Config()
    assert cfg.detection.median_ksize == 15
    assert cfg.publish.unicast == (("127.0.0.1", 47800),)
    assert cfg.publish.multicast_group == ""  # multicast is opt-in


def test_shipped_config_files_load():
    for path in sorted((ROOT / "config").glob("*.yaml")):
        load_config(path)


def test_dump_round_trips():
    cfg = load_config(ROOT / "config" / "rangebearing.yaml")
    again = load_config_text(dump_config(cfg))
    assert dataclass_equal(again, cfg)


def load_config_text(text):
    import yaml

    return config_from_mapping(yaml.safe_load(text))


SECTIONS = ("camera", "landmark", "detection", "model", "identity", "source", "publish", "daemon")


def dataclass_equal(a, b):
    return {k: getattr(a, k) for k in SECTIONS} == {k: getattr(b, k) for k in SECTIONS}


def test_every_problem_is_named_at_once(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "camera: {fx_px: -3, colour: red}\n"
        "detection: {median_ksize: 14, method: magic}\n"
        "publish: {unicast: [nohostport], multicast_group: 10.0.0.1}\n"
        "extra: 1\n"
    )
    with pytest.raises(ConfigError) as err:
        load_config(bad)
    msg = str(err.value)
    assert str(bad) in msg
    for key in (
        "camera.fx_px",
        "camera.colour",
        "detection.median_ksize",
        "detection.method",
        "publish.unicast",
        "publish.multicast_group",
        "'extra'",
    ):
        assert key in msg, key
    assert len(err.value.problems) == 7
    assert isinstance(err.value, ValueError)


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("camera: [1, 2]\n", "camera: must be a mapping"),
        ("- just\n- a list\n", "top level must be a mapping"),
        ("camera: {fx_px: 1\n", "not valid YAML"),
        ("detection: {red_hue: [[0, 200]]}\n", "detection.red_hue"),
        ("model: {envelope_range_m: [2.0, 0.1]}\n", "model.envelope_range_m"),
        ("landmark: {band_height_m: 0.04}\n", "two bands do not fit"),
        ("detection: {tracking: 'yes'}\n", "expected true or false"),
        ("source: {controls: {aeenable: 1}}\n", "source.controls"),
        ("detection: {full_scan_interval_s: -0.1}\n", "detection.full_scan_interval_s"),
        ("detection: {full_scan_interval_s: 1e9}\n", "detection.full_scan_interval_s"),
    ],
)
def test_specific_problems(tmp_path, text, fragment):
    f = tmp_path / "c.yaml"
    f.write_text(text)
    with pytest.raises(ConfigError, match=None) as err:
        load_config(f)
    assert fragment in str(err.value)


def test_missing_file_is_a_config_error(tmp_path):
    with pytest.raises(ConfigError, match="cannot read file"):
        load_config(tmp_path / "nope.yaml")


def test_cli_reports_bad_config_without_traceback(tmp_path):
    f = tmp_path / "c.yaml"
    f.write_text("camera: {fx_px: -3}\ndetection: {downscale: 9}\n")
    proc = subprocess.run(
        [sys.executable, "-m", "rangebearing.cli.main", "run", "--config", str(f), "--check"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 2
    assert proc.stderr.startswith("rangebearing: error:")
    assert "camera.fx_px" in proc.stderr and "detection.downscale" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_zenoh_section_defaults_off_and_round_trips():
    cfg = load_config(ROOT / "config" / "rangebearing.yaml")
    z = cfg.publish.zenoh
    assert not z.enabled and z.mode == "peer" and z.connect == () and z.listen == ()
    assert z.scouting_multicast and z.key == "rangebearing/{robot}/readings"
    on = config_from_mapping({"publish": {"robot_id": "zumo4", "zenoh": {
        "enabled": True, "mode": "client", "connect": ["tcp/10.0.0.1:7447"], "scouting_multicast": False}}})
    assert on.publish.zenoh.connect == ("tcp/10.0.0.1:7447",) and on.publish.unicast == (("127.0.0.1", 47800),)
    assert load_config_text(dump_config(on)).publish == on.publish


def test_every_zenoh_problem_is_named():
    with pytest.raises(ConfigError) as err:
        config_from_mapping({"publish": {"robot_id": "zumo1", "zenoh": {
            "enabled": "yes", "mode": "router", "connect": ["10.0.0.1:7447"], "listen": "tcp/0.0.0.0:7447",
            "key": "rangebearing/*/readings", "colour": 1}}})
    msg = str(err.value)
    for key in ("publish.zenoh.enabled", "publish.zenoh.mode", "publish.zenoh.connect", "publish.zenoh.listen",
                "publish.zenoh.key", "publish.zenoh.colour"):
        assert key in msg, key
    assert len(err.value.problems) == 6
    with pytest.raises(ConfigError) as err:  # robot ids are plain names, so each is one Zenoh key chunk
        config_from_mapping({"publish": {"robot_id": "a/b", "zenoh": {"enabled": True, "mode": "client"}}})
    assert "publish.robot_id" in str(err.value) and "client mode needs" in str(err.value)
    with pytest.raises(ConfigError, match="must contain"):
        config_from_mapping({"publish": {"zenoh": {"key": "rangebearing/readings"}}})
