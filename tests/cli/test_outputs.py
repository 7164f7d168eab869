"""Nothing a user owns is overwritten: outputs never land on inputs, existing files and
non-empty folders need --overwrite, writes are atomic; calibrate and record fail early."""

from __future__ import annotations

import builtins
import shutil
from pathlib import Path
from typing import Any

import pytest

from rangebearing.cli.main import main

CLIP = Path(__file__).resolve().parents[2] / "samples" / "clip"


@pytest.fixture
def clip(tmp_path: Path) -> Path:
    dest = tmp_path / "clip"
    shutil.copytree(CLIP, dest)
    return dest


def _snapshot(folder: Path) -> dict:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def test_replay_annotate_into_the_source_frames_is_refused(clip: Path, capsys: Any) -> None:
    before = _snapshot(clip)
    assert main(["replay", str(clip), "--annotate", str(clip), "-q"]) != 0
    assert "will not write into" in capsys.readouterr().err
    assert _snapshot(clip) == before


def test_replay_out_onto_the_truth_csv_is_refused_even_with_overwrite(clip: Path, capsys: Any) -> None:
    truth = next(clip.glob("*.csv"))
    before = truth.read_bytes()
    assert main(["replay", str(clip), "--truth", str(truth), "--out", str(truth), "-q", "--overwrite"]) != 0
    assert "will not write" in capsys.readouterr().err and truth.read_bytes() == before


def test_replay_out_over_an_existing_file_needs_overwrite(clip: Path, tmp_path: Path, capsys: Any) -> None:
    out = tmp_path / "readings.jsonl"
    out.write_text("mine\n")
    assert main(["replay", str(clip), "--out", str(out), "-q"]) != 0
    assert "--overwrite replaces it" in capsys.readouterr().err and out.read_text() == "mine\n"
    assert main(["replay", str(clip), "--out", str(out), "-q", "--overwrite"]) == 0
    assert out.read_text().count("\n") == len(list(clip.glob("*.jpg")))
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".readings")]  # no temporary left


def test_replay_annotate_into_a_non_empty_folder_needs_overwrite(clip: Path, tmp_path: Path) -> None:
    ann = tmp_path / "ann"
    ann.mkdir()
    (ann / "keep.txt").write_text("x")
    assert main(["replay", str(clip), "--annotate", str(ann), "-q"]) != 0
    assert [p.name for p in ann.iterdir()] == ["keep.txt"]


def test_calibrate_out_onto_the_truth_is_refused_before_any_fit(clip: Path, capsys: Any) -> None:
    truth = next(clip.glob("*.csv"))
    before = truth.read_bytes()
    assert main(["calibrate", str(clip), "--truth", str(truth), "--out", str(truth), "--overwrite"]) != 0
    err = capsys.readouterr().err
    assert "will not write" in err and truth.read_bytes() == before and "calibrate [" not in err


def test_calibrate_plot_without_matplotlib_fails_before_the_fit(clip: Path, tmp_path: Path, capsys: Any,
                                                                monkeypatch: pytest.MonkeyPatch) -> None:
    real_import = builtins.__import__

    def no_matplotlib(name: str, *args: Any, **kw: Any) -> Any:
        if name.startswith("matplotlib"):
            raise ImportError("No module named 'matplotlib'")
        return real_import(name, *args, **kw)

    monkeypatch.setattr(builtins, "__import__", no_matplotlib)
    out = tmp_path / "c.yaml"
    truth = next(clip.glob("*.csv"))
    assert main(["calibrate", str(clip), "--truth", str(truth), "--out", str(out), "--plot",
                 str(tmp_path / "p.png")]) != 0
    assert "needs matplotlib" in capsys.readouterr().err and not out.exists()


def test_calibrate_plot_into_a_missing_folder_fails_before_the_fit(clip: Path, tmp_path: Path, capsys: Any) -> None:
    out = tmp_path / "c.yaml"
    truth = next(clip.glob("*.csv"))
    assert main(["calibrate", str(clip), "--truth", str(truth), "--out", str(out), "--plot",
                 str(tmp_path / "nope" / "p.png")]) != 0
    assert "No such file or directory" in capsys.readouterr().err and not out.exists()


def test_record_into_an_existing_recording_is_refused(clip: Path, tmp_path: Path, capsys: Any) -> None:
    before = _snapshot(clip)
    assert main(["record", "--source", str(CLIP), "--out", str(clip), "--frames", "3"]) != 0
    assert "not empty" in capsys.readouterr().err and _snapshot(clip) == before


def test_record_does_not_create_out_when_the_source_fails(tmp_path: Path) -> None:
    out = tmp_path / "new"
    assert main(["record", "--source", str(tmp_path / "missing"), "--out", str(out), "--frames", "3"]) != 0
    assert not out.exists()


def test_record_from_files_keeps_every_frame_under_its_own_name(tmp_path: Path) -> None:
    out = tmp_path / "copy"
    assert main(["record", "--source", str(CLIP), "--fps", "5", "--out", str(out), "--frames", "26",
                 "--format", "png"]) == 0
    assert sorted(p.stem for p in out.iterdir()) == sorted(p.stem for p in CLIP.glob("*.jpg"))
