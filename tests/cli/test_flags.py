"""Command-line flags mean what they say (item 18): nothing silently ignored or guessed."""

from __future__ import annotations

from pathlib import Path
from typing import Any, List

import pytest

from rangebearing.cli.main import main

CLIP = Path(__file__).resolve().parents[2] / "samples" / "clip"


@pytest.mark.parametrize("argv, says", [
    (["run", "--json", "--check"], "--json only applies with --echo"),
    (["run", "--source", "opencv:", "--check"], "name the device"),
    (["run", "--source", "webcam", "--check"], "neither a source kind"),
    (["record", "--source", "webcam", "--out", "x", "--frames", "1"], "neither a source kind"),
    (["run", "--fps", "nan", "--check"], "--fps: must be a number from 0 to 1000, got nan"),
    (["run", "--fps", "1e400", "--check"], "--fps: must be a number from 0 to 1000, got inf"),
    (["run", "--fps", "-1", "--check"], "--fps: must be a number from 0 to 1000"),
    (["record", "--fps", "inf", "--source", str(CLIP), "--out", "x", "--frames", "1"], "--fps: must be a number"),
    (["run", "--source", "", "--check"], "--source: empty"),
    (["run", "--source", " ", "--check"], "--source: empty"),
    (["run", "--source", "picamera2:17", "--check"], "an integer from 0 to 16"),
    (["run", "--source", "picamera2:-1", "--check"], "an integer from 0 to 16"),
    (["run", "--source", str(CLIP), "--record", "x.mcap", "--record-max-mb", "1e-9"], "--record-max-mb: at least 1"),
])
def test_flags_that_mean_nothing_are_refused(argv: List[str], says: str, capsys: Any) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("rangebearing: error:") and says in err


def test_the_largest_fps_and_camera_number_are_accepted(capsys: Any) -> None:
    assert main(["run", "--fps", "1000", "--source", "picamera2:16", "--check"]) == 0


def test_verbose_is_accepted_after_the_subcommand(capsys: Any) -> None:
    assert main(["run", "-v", "--check"]) == 0
    assert main(["run", "--source", str(CLIP), "--check", "-v"]) == 0


def test_an_existing_folder_is_still_a_recorded_source(capsys: Any) -> None:
    assert main(["run", "--source", str(CLIP), "--check"]) == 0
