"""The one error funnel: every error a user can cause is one ``rangebearing: error:`` line and a non-zero exit."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import List

import pytest

from rangebearing.cli.main import chosen_command, main

REPO = Path(__file__).resolve().parents[2]
CLIP = REPO / "samples" / "clip"


def one_error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err
    errors = [ln for ln in lines if ln.startswith("rangebearing: error: ")]
    assert len(errors) == 1, err
    return errors[0]


def test_replay_out_into_a_missing_folder(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["replay", str(CLIP), "--out", "/nonexistent/dir/x.jsonl", "-q"]) == 1
    line = one_error_line(capsys.readouterr().err)
    assert "/nonexistent/dir/x.jsonl" in line and "No such file" in line


def test_replay_annotate_onto_an_existing_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "a_file"
    target.write_text("mine")
    assert main(["replay", str(CLIP), "--annotate", str(target), "-q"]) == 1
    assert "is not a folder" in one_error_line(capsys.readouterr().err)
    assert target.read_text() == "mine"


def test_calibrate_plot_to_an_unwritable_path(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    frames = tmp_path / "cal"
    assert main(["synth", "--out", str(frames), "--frames", "8", "--seed", "5", "--preset", "paper"]) == 0
    code = main(["calibrate", str(frames), "--truth", str(frames / "truth.csv"), "--out", str(tmp_path / "c.yaml"),
                 "--plot", "/nonexistent/dir/plot.png"])
    assert code == 1
    assert "/nonexistent/dir/plot.png" in one_error_line(capsys.readouterr().err)


def test_a_bad_config_exits_2_and_names_the_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("detection: {median_ksize: 4}\n")
    assert main(["run", "--config", str(bad), "--check"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"rangebearing: error: {bad}: 1 problem") and "Traceback" not in err


def test_debug_shows_the_traceback(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(OSError):
        main(["--debug", "replay", str(CLIP), "--out", "/nonexistent/dir/x.jsonl", "-q"])
    with pytest.raises(OSError):  # also after the command name
        main(["replay", "--debug", str(CLIP), "--out", "/nonexistent/dir/x.jsonl", "-q"])


def test_debug_from_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("RANGEBEARING_DEBUG", "1")
    with pytest.raises(OSError):
        main(["replay", str(CLIP), "--out", "/nonexistent/dir/x.jsonl", "-q"])


def test_an_unexpected_exception_is_one_line_too(monkeypatch: pytest.MonkeyPatch,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    from rangebearing.cli import replay_cmd

    def boom(args: object) -> int:
        raise KeyError("surprise")

    monkeypatch.setattr(replay_cmd, "run", boom)
    assert main(["replay", str(CLIP)]) == 1
    line = one_error_line(capsys.readouterr().err)
    assert "KeyError" in line and "--debug" in line


@pytest.mark.parametrize("argv, expected", [
    (["run", "--check"], "run"), (["-v", "replay", "x"], "replay"), (["--debug", "listen"], "listen"),
    (["--help"], None), (["nonsense"], None), ([], None),
])
def test_the_command_is_found_without_importing_the_others(argv: List[str], expected: object) -> None:
    assert chosen_command(argv) == expected


def test_help_lists_every_command(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(["--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    for name in ("run", "listen", "replay", "calibrate", "record", "synth"):
        assert name in out


def imported_modules(*argv: str) -> List[str]:
    """The rangebearing modules a fresh interpreter has loaded after ``rangebearing ARGV``.

    (``python -X importtime`` shows the same list with timings; ``sys.modules`` is what the test reads.)
    """
    env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
    code = ("import sys; from rangebearing.cli.main import main; code = main(sys.argv[1:]); "
            "print(*sorted(m for m in sys.modules if m.startswith(('rangebearing', 'http')))); sys.exit(code)")
    proc = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, env=env, cwd=REPO,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return proc.stdout.splitlines()[-1].split()


def test_run_check_loads_only_what_the_daemon_needs() -> None:
    mods = imported_modules("run", "--config", "config/demo.yaml", "--check")
    assert "rangebearing.daemon.loop" in mods and "rangebearing.cli.run_cmd" in mods  # the measurement works
    not_needed = ("rangebearing.synth", "rangebearing.evaluation", "rangebearing.recording")
    http_server = ("rangebearing.view.server", "rangebearing.view.handler", "rangebearing.view.hub", "http.server")
    unwanted = [m for m in mods if m.startswith(not_needed) or m in http_server
                or m == "rangebearing.core.fit" or (m.startswith("rangebearing.cli.") and m.endswith("_cmd")
                                                    and m != "rangebearing.cli.run_cmd")]
    assert unwanted == []


@pytest.mark.parametrize("closed", [1, 2])
def test_a_command_started_with_stdout_or_stderr_closed_runs_to_the_end(closed: int) -> None:
    """``rangebearing replay clip >&-`` (Python then has no sys.stdout): the frames are replayed, nothing crashes."""
    proc = subprocess.run([sys.executable, "-m", "rangebearing.cli.main", "replay", str(CLIP)],
                          stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=120,
                          preexec_fn=lambda: os.close(closed))
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-2000:]
    assert "a bug?" not in proc.stdout + proc.stderr and "Traceback" not in proc.stdout + proc.stderr


def test_a_console_that_cannot_show_the_units_gets_them_replaced_not_an_error() -> None:
    """An ASCII stdout (PYTHONIOENCODING=ascii, an old serial console) cannot encode "±" or "°"."""
    proc = subprocess.run([sys.executable, "-m", "rangebearing.cli.main", "replay", str(CLIP)],
                          stdin=subprocess.DEVNULL, capture_output=True, timeout=120,
                          env={**os.environ, "PYTHONIOENCODING": "ascii"})
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert b" m ?" in proc.stdout and b"a bug?" not in proc.stderr  # "0.697 m ?0.9 mm": replaced, every frame
