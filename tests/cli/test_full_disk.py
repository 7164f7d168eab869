"""Outputs that cannot be written: refused before the work, or one error line naming the file, and no litter.

A full disk is stood in for by a file-size limit (RLIMIT_FSIZE: the write fails with EFBIG where a full disk
gives ENOSPC; both are an OSError on write or close), so the tests need no root and no tmpfs.
"""

from __future__ import annotations

import errno
import io
import os
import resource
import signal
import subprocess
import sys
from pathlib import Path
from typing import Callable, List, Tuple

import pytest

from rangebearing.cli.main import main
from rangebearing.core.types import CameraIntrinsics
from rangebearing.synth.dataset import write_dataset

TIMEOUT_S = 180.0  # a loaded machine: what happened is asserted, not how fast


@pytest.fixture(scope="module")
def frames(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("paper")
    write_dataset(d, 8, seed=20810, preset="paper", camera=CameraIntrinsics().scaled(320, 240))
    return d


def _file_size_limit(limit_bytes: int) -> Callable[[], None]:
    def apply() -> None:  # in the child, before exec
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails (EFBIG) instead of killing
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))
    return apply


def rangebearing_limited(limit_bytes: int, scratch: Path, *argv: str) -> Tuple[int, str]:
    proc = subprocess.run([sys.executable, "-m", "rangebearing.cli.main", *argv], stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=TIMEOUT_S, preexec_fn=_file_size_limit(limit_bytes),
                          env={**os.environ, "RANGEBEARING_CACHE": "off", "MPLCONFIGDIR": str(scratch)})
    assert "Traceback" not in proc.stderr and "a bug?" not in proc.stderr, proc.stderr
    return proc.returncode, proc.stderr


def error_lines(err: str) -> List[str]:
    return [ln for ln in err.splitlines() if ln.startswith("rangebearing: error:")]


def litter(folder: Path) -> List[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def test_replay_out_on_a_full_disk_is_one_error_naming_it_and_leaves_nothing(frames: Path, tmp_path: Path) -> None:
    out = tmp_path / "readings.jsonl"
    status, err = rangebearing_limited(300, tmp_path.parent / "mpl", "replay", str(frames), "-q", "--out", str(out))
    assert status == 1
    assert error_lines(err) == [f"rangebearing: error: cannot write {out}: File too large"], err
    assert not out.exists() and litter(tmp_path) == []  # no half file, no temporary one


def test_calibrate_plot_on_a_full_disk_keeps_the_config_and_leaves_no_half_plot(frames: Path,
                                                                                tmp_path: Path) -> None:
    out, plot = tmp_path / "cal.yaml", tmp_path / "fit.png"
    status, err = rangebearing_limited(8000, tmp_path.parent / "mpl", "calibrate", str(frames),
                                       "--truth", str(frames / "truth.csv"), "--out", str(out), "--plot", str(plot),
                                       "-q")
    assert status == 1
    assert error_lines(err) == [f"rangebearing: error: cannot write {plot}: File too large"], err
    assert out.is_file() and "model:" in out.read_text()  # the fit is kept
    assert not plot.exists() and litter(tmp_path) == []


def test_a_plot_format_matplotlib_lacks_is_refused_before_the_fit(frames: Path, tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "cal.yaml"
    assert main(["calibrate", str(frames), "--truth", str(frames / "truth.csv"), "--out", str(out),
                 "--plot", str(tmp_path / "fit.xyz"), "-q"]) != 0
    err = capsys.readouterr().err
    assert error_lines(err) == [next(ln for ln in err.splitlines() if "matplotlib cannot write" in ln)], err
    assert "a bug?" not in err and not out.exists()  # refused before the fit: nothing written


@pytest.mark.parametrize("command", [
    ["intrinsics", "{frames}", "--board", "9x6", "--square-mm", "25", "-q"],
    ["tune", "--source", "{frames}", "--loop", "--settle", "1", "--frames", "2", "--fps", "0"],
])
@pytest.mark.parametrize("onto, says", [("{frames}/000000.png", "it is a frame of"),
                                        ("{frames}", "is a folder"),
                                        ("{tmp}/missing/out.yaml", "does not exist")])
def test_intrinsics_and_tune_refuse_an_out_they_cannot_or_must_not_write_before_the_work(
        frames: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], command: List[str], onto: str,
        says: str) -> None:
    before = (frames / "000000.png").read_bytes()
    argv = [a.format(frames=frames) for a in command] + ["--out", onto.format(frames=frames, tmp=tmp_path)]
    assert main(argv) == 1
    out, err = capsys.readouterr()
    assert len(error_lines(err)) == 1 and says in error_lines(err)[0] and "--out" in error_lines(err)[0], err
    assert "board" not in out and "thresholds" not in out  # refused before any frame was read
    assert (frames / "000000.png").read_bytes() == before and not (frames / "000000.png.bak").exists()


@pytest.mark.parametrize("command", [["run", "--fps", "0", "--record"], ["record", "--frames", "2", "--out"]])
def test_a_recording_that_cannot_even_start_on_a_full_disk_is_one_error_and_no_empty_file(
        frames: Path, tmp_path: Path, command: List[str]) -> None:
    out = tmp_path / "rec.mcap"
    status, err = rangebearing_limited(0, tmp_path.parent / "mpl", command[0], "--source", str(frames),
                                       *command[1:], str(out), *(["-q"] if command[0] == "record" else []))
    assert status == 1
    assert len(error_lines(err)) == 1 and str(out) in error_lines(err)[0] and "File too large" in err, err
    assert not out.exists()


class _FullStream(io.StringIO):
    """stdout on a full disk (``> /dev/full``): every write that reaches the file fails with ENOSPC."""

    def flush(self) -> None:
        if self.getvalue():
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


class _ClosedPipe(io.StringIO):
    """stdout to a reader that went away (``| head`` done)."""

    def flush(self) -> None:
        if self.getvalue():
            raise BrokenPipeError(errno.EPIPE, os.strerror(errno.EPIPE))


@pytest.mark.parametrize("argv", [["--help"], ["replay", "--help"], ["--version"]])
def test_help_and_version_that_cannot_be_written_are_a_write_error(
    argv: List[str], monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(sys, "stdout", _FullStream())
    assert main(argv) == 1  # argparse alone drops the OSError and exits 0
    assert capsys.readouterr().err == f"rangebearing: error: {os.strerror(errno.ENOSPC)}\n"
    monkeypatch.setattr(sys, "stdout", _ClosedPipe())
    monkeypatch.setattr("rangebearing.cli.main._silence_stdout", lambda: None)
    assert main(argv) == 0  # `--help | head` stays quiet, as any other command's output does
    assert capsys.readouterr().err == ""


def test_help_to_dev_full_exits_non_zero(tmp_path: Path) -> None:
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "rangebearing.cli.main", "--help"], stdout=full,
                              stderr=subprocess.PIPE, text=True, timeout=TIMEOUT_S)
    assert proc.returncode == 1 and proc.stderr.startswith("rangebearing: error: No space left"), proc.stderr
