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
])
def test_flags_that_mean_nothing_are_refused(argv: List[str], says: str, capsys: Any) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("rangebearing: error:") and says in err


def test_verbose_is_accepted_after_the_subcommand(capsys: Any) -> None:
    assert main(["run", "-v", "--check"]) == 0
    assert main(["run", "--source", str(CLIP), "--check", "-v"]) == 0


def test_an_existing_folder_is_still_a_recorded_source(capsys: Any) -> None:
    assert main(["run", "--source", str(CLIP), "--check"]) == 0
