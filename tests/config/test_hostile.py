"""Config files a careless user or a hostile one writes: each is one ConfigError naming the
file (and the key or line), quickly, with a short message; nothing else ever escapes."""

from __future__ import annotations

import time
from pathlib import Path

import cv2
import pytest

from rangebearing.config import Config, check, load_config
from rangebearing.config.load import config_from_mapping
from rangebearing.core.pipeline import Pipeline
from rangebearing.errors import ConfigError
from rangebearing.net.fit import landmarks_that_fit

BOMB = "\n".join(
    ["a0: &a0 [x, x, x, x, x, x, x, x, x]"]
    + [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 9)]
    + ["detection: {red_hue: *a8}"]
)


def _load(tmp_path: Path, content: str | bytes, name: str = "c.yaml") -> ConfigError:
    f = tmp_path / name
    if isinstance(content, bytes):
        f.write_bytes(content)
    else:
        f.write_text(content, encoding="utf-8")
    t0 = time.thread_time()
    with pytest.raises(ConfigError) as info:
        load_config(f)
    assert time.thread_time() - t0 < 1.0
    err = info.value
    assert type(err) is ConfigError and str(f) in str(err) and len(str(err)) < 2048
    return err


HOSTILE = {  # item 5: each escaped load_config as another exception
    "not UTF-8": (b"publish: {robot_id: zu\xffmo}\n", "not UTF-8"),
    "nesting 2,000 deep": ("camera: " + "[" * 2000 + "]" * 2000 + "\n", "nesting deeper than"),
    "nesting as block mappings": ("".join(f"{' ' * i}k{i}:\n" for i in range(200)) + " " * 200 + "v\n",
                                  "nesting deeper than"),
    "a 5,000-digit integer": ("camera: {fx_px: " + "9" * 5000 + "}\n", "digits is not a setting"),
    "an integer of 10**309": ("camera: {fx_px: 1" + "0" * 309 + "}\n", "digits is not a setting"),
    "a 100-digit integer": ("camera: {cx_px: 1" + "0" * 99 + "}\n", "camera.cx_px: must be a number from 0 to"),
    "1e400": ("camera: {fx_px: 1e400}\n", "camera.fx_px: must be a number from 1 to 1e+06"),
    "superscript digits in multicast_group": ('publish: {multicast_group: "\u00b2.1.1.1"}\n', "multicast"),
    "a NUL in a path": ('source: {kind: recorded, path: "clip\\0x"}\n', "source.path: contains the control"),
    "a NUL in the device": ('source: {kind: opencv, device: "/dev/video0\\0"}\n', "source.device"),
    "a timestamp": ("camera: {fx_px: 2001-12-14}\n", "camera.fx_px"),
    "an invalid date": ("camera: {fx_px: 2001-13-45}\n", "not valid YAML"),
    "a control character": ("camera: {fx_px: 1\x07}\n", "not valid YAML"),
    "a binary tag": ("camera: {fx_px: !!binary AAAA}\n", "camera.fx_px"),
    "a python tag": ("camera: !!python/object:os.system {}\n", "not valid YAML"),
}


@pytest.mark.parametrize("content, fragment", HOSTILE.values(), ids=list(HOSTILE))
def test_hostile_values_are_config_errors_naming_the_file(tmp_path: Path, content: str | bytes,
                                                         fragment: str) -> None:
    assert fragment in str(_load(tmp_path, content))


def test_a_nul_in_the_config_path_itself(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="cannot read file"):
        load_config(str(tmp_path / "c\0.yaml"))


def test_an_alias_bomb_is_refused_quickly_and_briefly(tmp_path: Path) -> None:  # item 6
    err = _load(tmp_path, BOMB)
    assert "alias" in str(err) and len(str(err)) < 300


def test_a_recursive_alias_is_refused(tmp_path: Path) -> None:
    assert "alias" in str(_load(tmp_path, "detection: {red_hue: &r [*r]}\n"))


def test_a_few_aliases_are_fine(tmp_path: Path) -> None:
    f = tmp_path / "c.yaml"
    f.write_text("detection: {red_hue: &h [[0, 10]], blue_hue: *h}\n")
    assert load_config(f).detection.blue_hue == ((0, 10),)


def test_a_huge_file_is_refused_unread(tmp_path: Path) -> None:
    assert "larger than" in str(_load(tmp_path, "# " + "x" * 200_000 + "\n"))


def test_a_long_value_is_cut_in_the_message(tmp_path: Path) -> None:
    err = _load(tmp_path, "detection: {method: " + "m" * 60_000 + "}\n")
    assert len(str(err)) < 300 and "…" in str(err)


# --- item 9: what validation says ------------------------------------------------------


def test_every_bad_list_entry_is_reported(tmp_path: Path) -> None:
    err = _load(tmp_path, 'publish: {unicast: ["a:1", "nohostport", "b:99999", "c:2", "127.0.0.1:x"]}\n'
                          "detection: {red_hue: [[0, 10], [0, 400], [9, 3]]}\n")
    text = str(err)
    for where in ("publish.unicast[1]", "publish.unicast[2]", "publish.unicast[4]", "detection.red_hue[1]",
                  "detection.red_hue[2]"):
        assert where in text, where
    assert "unicast[0]" not in text and "unicast[3]" not in text and len(err.problems) == 5


def test_a_flat_hue_range_is_refused_with_the_fix(tmp_path: Path) -> None:
    err = _load(tmp_path, "detection: {red_hue: [0, 10]}\n")
    assert "detection.red_hue" in str(err) and "write [[0, 10]]" in str(err)


def test_duplicate_destinations_are_refused(tmp_path: Path) -> None:
    err = _load(tmp_path, 'publish: {unicast: ["127.0.0.1:47800", "LocalHost:5", "localhost:5"]}\n')
    assert "publish.unicast[2]: same destination as [1]" in str(err) and len(err.problems) == 1


def test_duplicate_yaml_keys_are_refused_with_both_lines(tmp_path: Path) -> None:
    err = _load(tmp_path, "camera:\n  fx_px: 600\n  fx_px: 700\ncamera:\n  fy_px: 1\n")
    text = str(err)
    assert "line 3: duplicate key 'fx_px' (first at line 2)" in text
    assert "line 4: duplicate key 'camera' (first at line 1)" in text


def test_yaml_booleans_where_a_word_is_expected_say_so(tmp_path: Path) -> None:
    err = _load(tmp_path, "detection: {white_balance: off}\n")
    assert "YAML boolean false" in str(err) and "grey_world, none" in str(err)
    assert "False is not" not in str(err)


@pytest.mark.parametrize("text, says", [
    ("camera: {fx_px: -1}\n", "camera.fx_px: must be a number from 1 to 1e+06, got -1"),
    ("camera: {fx_px: 0}\n", "camera.fx_px: must be a number from 1 to 1e+06, got 0"),
    ("detection: {downscale: 9}\n", "detection.downscale: must be an integer from 1 to 4, got 9"),
    ("detection: {downscale: 1.5}\n", "must be an integer from 1 to 4, got 1.5"),
    ("source: {fps: -1}\n", "source.fps: must be a number from 0 to 1000, got -1"),
])
def test_range_messages_say_what_is_allowed(tmp_path: Path, text: str, says: str) -> None:
    assert says in str(_load(tmp_path, text))


def test_yaml_syntax_errors_name_the_file_and_line(tmp_path: Path) -> None:
    err = _load(tmp_path, "camera:\n  fx_px: 600\n  fy_px: [1, 2\n")
    assert "<unicode string>" not in str(err) and "not valid YAML: line" in str(err)


# --- item 7: what a deployment can reach -------------------------------------------------


@pytest.mark.parametrize("text, says", [
    ('publish: {robot_id: ""}\n', "publish.robot_id: must be 1-64"),
    ("publish: {robot_id: " + "r" * 60_000 + "}\n", "publish.robot_id: must be 1-64"),
    ("publish: {robot_id: " + "r" * 70_000 + "}\n", "larger than 64 KiB"),
    ('publish: {robot_id: "zumo 7"}\n', "publish.robot_id"),
    ('publish: {robot_id: "\\ud800"}\n', "publish.robot_id"),
    ('publish: {robot_id: "a\\nb"}\n', "publish.robot_id"),
    ("detection: {max_landmarks: 1000}\n", "detection.max_landmarks: must be an integer from 1 to 64, got 1000"),
    ("publish: {unicast: [" + ", ".join(f'"127.0.0.1:{p}"' for p in range(1, 2000)) + "]}\n",
     "publish.unicast: 1999 entries; at most 32"),
    ("source: {timeout_s: 4, retries: 10}\n", "source.timeout_s × source.retries: 40 s"),
    ("source: {timeout_s: 60}\n", "source.timeout_s: must be a number > 0 and <= 4"),
    ("daemon: {status_interval_s: 1e9}\n", "daemon.status_interval_s"),
])
def test_check_refuses_what_can_never_publish(tmp_path: Path, text: str, says: str) -> None:
    assert says in str(_load(tmp_path, text))


def test_max_landmarks_is_not_bounded_by_the_datagram(tmp_path: Path) -> None:
    """More landmarks than one packet holds are detected and tracked; the wire sends the nearest that fit."""
    fit = landmarks_that_fit("zumo")
    f = tmp_path / "ok.yaml"
    f.write_text(f"detection: {{max_landmarks: {2 * fit}}}\n")
    assert load_config(f).detection.max_landmarks == 2 * fit
    assert Config().detection.max_landmarks > fit  # the default detects a crowd larger than one packet holds


def test_the_defaults_pass_their_own_checks() -> None:
    check(Config())
    shipped = Path(__file__).resolve().parents[2] / "config"
    for f in sorted(shipped.glob("*.yaml")):
        check(load_config(f))


@pytest.mark.parametrize("text, says", [
    ("landmark: {diameter_m: 1.0e-9}\n", "landmark.diameter_m: must be a number from 0.001 to 10, got 1e-09"),
    ("landmark: {diameter_m: 1.0e+308}\n", "landmark.diameter_m: must be a number from 0.001 to 10"),
    ("landmark: {height_m: 1.0e+308}\n", "landmark.height_m: must be a number from 0.001 to 10"),
    ("landmark: {band_height_m: 5.0e-324}\n", "landmark.band_height_m: must be a number from 0.001 to 10"),
    ("camera: {fx_px: 1.0e-300}\n", "camera.fx_px: must be a number from 1 to 1e+06"),
    ("camera: {fy_px: 1.0e+308}\n", "camera.fy_px: must be a number from 1 to 1e+06"),
    ("camera: {width_px: 1.0e+308}\n", "camera.width_px: must be an integer from 1 to 10000"),
])
def test_sizes_that_hang_or_overflow_the_pipeline_are_refused(tmp_path: Path, text: str, says: str) -> None:
    """A 1e-9 m landmark made the search look for nanometre bands (minutes a frame); 1e308 m or a focal
    length of 1e-300 px overflowed the projection (OverflowError out of Pipeline.process)."""
    assert says in str(_load(tmp_path, text))


@pytest.mark.parametrize("landmark, fx_px", [((0.0031, 0.001, 0.001), 1.0), ((10.0, 10.0, 1.0), 1e6),
                                             ((10.0, 0.001, 4.0), 1.0)])
def test_the_extremes_allowed_run_the_pipeline(landmark: tuple, fx_px: float) -> None:
    h, d, b = landmark
    cfg = config_from_mapping({"landmark": {"height_m": h, "diameter_m": d, "band_height_m": b},
                               "camera": {"fx_px": fx_px, "fy_px": fx_px}})
    frame = cv2.imread(str(Path(__file__).resolve().parents[2] / "samples" / "clip" / "000000.jpg"))
    pipe = Pipeline(cfg.pipeline, track=True)
    for _ in range(2):
        pipe.process(frame)  # raises nothing, in well under a second


@pytest.mark.parametrize("text, hint", [("landmark: {diameter_m: 35e-3}\n", True), ("camera: {fx_px: '634'}\n", True),
                                        ("camera: {fx_px: lots}\n", False), ("camera: {fx_px: 1e999}\n", False)])
def test_a_number_yaml_reads_as_text_says_how_to_write_it(tmp_path: Path, text: str, hint: bool) -> None:
    """YAML 1.1 reads 35e-3 (no dot) as a string: 'must be a number, got '35e-3'' alone baffles."""
    assert ("with a dot before any exponent" in str(_load(tmp_path, text))) is hint
