"""Saving thresholds: in place with comments kept, old file as FILE.bak, never a half-written or invalid file."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from rangebearing.config import load_config
from rangebearing.errors import ConfigError, OutputError
from rangebearing.view import save as save_mod
from rangebearing.view.save import save_thresholds
from rangebearing.view.thresholds import Thresholds

REPO = Path(__file__).resolve().parents[2]
NEW = Thresholds(((0, 8), (170, 179)), ((100, 128),), 140, 40)


def check_saved(path: Path, old: bytes) -> None:
    det = load_config(path).detection
    assert Thresholds.of(det) == NEW
    assert (path.parent / (path.name + ".bak")).read_bytes() == old
    assert sorted(p.name for p in path.parent.iterdir()) == sorted([path.name, path.name + ".bak"])  # no temp left


def test_default_config_keeps_its_comments(tmp_path: Path) -> None:
    path = tmp_path / "rangebearing.yaml"
    shutil.copy(REPO / "config" / "rangebearing.yaml", path)
    old = path.read_bytes()
    os.chmod(path, 0o640)
    assert save_thresholds(path, NEW) == (path, tmp_path / "rangebearing.yaml.bak")
    check_saved(path, old)
    text = path.read_text()
    assert "s_min: 140              # minimum saturation (0-255)" in text
    assert "red_hue: [[0, 8], [170, 179]]   # OpenCV hue 0-179; red wraps around 0" in text
    assert len(text.splitlines()) == len(old.decode().splitlines())  # only those lines changed
    assert load_config(path).model == load_config(REPO / "config" / "rangebearing.yaml").model
    assert path.stat().st_mode & 0o777 == 0o640


def test_file_without_detection_gets_one(tmp_path: Path) -> None:
    path = tmp_path / "c.yaml"
    path.write_text("# demo\nsource: {kind: recorded, path: clip}\n")
    old = path.read_bytes()
    save_thresholds(path, NEW)
    check_saved(path, old)
    assert path.read_text().startswith("# demo\n")


def test_flow_style_and_block_lists_are_rewritten(tmp_path: Path) -> None:
    flow = "detection: {s_min: 10, tracking: false}\n"
    block = "detection:\n  red_hue:\n    - [0, 10]\n  tracking: false\n"
    for text in (flow, block):
        path = tmp_path / "c.yaml"
        path.write_text(text)
        save_thresholds(path, NEW)
        assert Thresholds.of(load_config(path).detection) == NEW
        assert load_config(path).detection.tracking is False  # the file's other keys kept
        (tmp_path / "c.yaml.bak").unlink()


def test_invalid_file_is_left_alone(tmp_path: Path) -> None:
    path = tmp_path / "c.yaml"
    path.write_text("detection:\n  s_min: 90\n  bogus: 1\n")
    with pytest.raises(ConfigError, match="bogus"):
        save_thresholds(path, NEW)
    assert path.read_text() == "detection:\n  s_min: 90\n  bogus: 1\n"
    assert not (tmp_path / "c.yaml.bak").exists()


def test_failed_rename_leaves_the_old_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "c.yaml"
    path.write_text("detection:\n  s_min: 90\n")
    real = os.replace
    calls = []

    def replace(src: str, dst: str) -> None:
        calls.append(dst)
        if str(dst) == str(path):
            raise OSError(28, "No space left on device")
        real(src, dst)

    monkeypatch.setattr(save_mod.os, "replace", replace)
    with pytest.raises(OutputError, match="No space left"):
        save_thresholds(path, NEW)
    assert path.read_text() == "detection:\n  s_min: 90\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.yaml", "c.yaml.bak"]  # the temp file removed


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(OutputError, match="cannot read"):
        save_thresholds(tmp_path / "nope.yaml", NEW)
