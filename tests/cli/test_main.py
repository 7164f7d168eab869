"""The command line: help, calibrate refusals and plots, record, synth → replay round trip."""

from __future__ import annotations

import builtins
import subprocess
import sys
from pathlib import Path

import pytest

from rangebearing import load_config
from rangebearing.cli.main import main
from rangebearing.synth import write_dataset


def test_help_lists_every_command(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--help"])
    assert exit_.value.code == 0
    out = capsys.readouterr().out
    for cmd in ("run", "replay", "calibrate", "synth", "record", "listen"):
        assert cmd in out


def test_calibrate_refuses_a_single_distance(tmp_path, capsys):
    frames = tmp_path / "f"
    write_dataset(frames, 6, 3, "paper")
    truth = frames / "truth.csv"
    rows = truth.read_text().splitlines()
    # rewrite every true range to one distance: the fit must refuse, naming why
    truth.write_text("\n".join([rows[0]] + [f"{r.split(',')[0]},0.500000,{r.split(',')[2]}" for r in rows[1:]]) + "\n")
    code = main(["calibrate", str(frames), "--truth", str(truth), "--out", str(tmp_path / "c.yaml")])
    assert code == 1
    assert "one distance only" in capsys.readouterr().err
    assert not (tmp_path / "c.yaml").exists()


def test_calibrate_refuses_frames_without_landmarks(tmp_path, capsys):
    frames = tmp_path / "f"
    write_dataset(frames, 8, 5, "clutter")
    empty = tmp_path / "t.csv"
    empty.write_text("frame,range_m,bearing_rad\n")
    assert main(["calibrate", str(frames), "--truth", str(empty), "--out", str(tmp_path / "c.yaml")]) == 1
    assert "no landmark was detected" in capsys.readouterr().err


def test_calibrate_plot(tmp_path, capsys, monkeypatch):
    frames = tmp_path / "f"
    write_dataset(frames, 12, 9, "wide")
    args = ["calibrate", str(frames), "--truth", str(frames / "truth.csv"), "--out", str(tmp_path / "c.yaml")]
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        assert main([*args, "--plot", str(tmp_path / "p.png")]) == 1
        assert "--plot needs matplotlib" in capsys.readouterr().err
    else:
        assert main([*args, "--plot", str(tmp_path / "p.png")]) == 0
        assert (tmp_path / "p.png").read_bytes()[:4] == b"\x89PNG"
        real_import = builtins.__import__

        def no_matplotlib(name, *a, **k):
            if name.startswith("matplotlib"):
                raise ImportError(name)
            return real_import(name, *a, **k)

        monkeypatch.setattr(builtins, "__import__", no_matplotlib)
        first = (tmp_path / "c.yaml").read_bytes()
        assert main([*args, "--overwrite", "--plot", str(tmp_path / "q.png")]) == 1
        assert "--plot needs matplotlib" in capsys.readouterr().err
        assert (tmp_path / "c.yaml").read_bytes() == first  # refused before the fit: nothing written
    load_config(tmp_path / "c.yaml")


def test_record_then_replay(tmp_path, static_clip, capsys):
    out = tmp_path / "rec"
    assert main(["record", "--out", str(out), "--frames", "5", "--source", str(static_clip), "--fps", "0"]) == 0
    assert sorted(p.name for p in out.iterdir()) == [f"{i:06d}.png" for i in range(5)]
    assert "recorded 5 frames" in capsys.readouterr().out
    assert main(["replay", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 5 and all(line.count(" m ") == 2 for line in lines)


def test_replay_of_a_missing_path_is_one_clear_error(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "rangebearing.cli.main", "replay", str(tmp_path / "nope")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 1
    assert proc.stderr.startswith("rangebearing: error:") and "Traceback" not in proc.stderr


def test_run_check_resolves_destinations_and_names_the_file(tmp_path, capsys, monkeypatch):
    import socket

    real = socket.getaddrinfo

    def no_dns(host, *args, **kw):  # never ask a real resolver from a test
        if host == "no-such-robot.invalid":
            raise socket.gaierror(socket.EAI_NONAME, "Name or service not known")
        return real(host, *args, **kw)

    monkeypatch.setattr(socket, "getaddrinfo", no_dns)
    cfg = tmp_path / "c.yaml"
    cfg.write_text('publish: {unicast: ["no-such-robot.invalid:47800"]}\nsource: {kind: synthetic}\n')
    assert main(["run", "--config", str(cfg), "--check"]) == 2
    err = capsys.readouterr().err
    assert f"{cfg}: 1 problem" in err and "no-such-robot.invalid" in err


def test_run_starts_with_the_destinations_that_resolve(tmp_path, monkeypatch):
    import socket

    from rangebearing.net.client import Subscriber

    real = socket.getaddrinfo

    def no_dns(host, *args, **kw):  # never ask a real resolver from a test
        if host == "no-such-robot.invalid":
            raise socket.gaierror(socket.EAI_AGAIN, "Temporary failure in name resolution")
        return real(host, *args, **kw)

    monkeypatch.setattr(socket, "getaddrinfo", no_dns)
    clip = Path(__file__).resolve().parents[2] / "samples" / "clip"
    with Subscriber(port=0, timeout_s=2.0) as sub:
        cfg = tmp_path / "c.yaml"
        cfg.write_text(f'publish: {{unicast: ["no-such-robot.invalid:47800", "127.0.0.1:{sub.port}"]}}\n'
                       f'source: {{kind: recorded, path: "{clip}", fps: 0}}\n')
        assert main(["run", "--config", str(cfg)]) == 0
        first = sub.recv()
    assert first is not None and first.seq == 0


@pytest.mark.parametrize("spec, message", [("picamera2:abc", "must be an integer"), ("recorded:", "source.path")])
def test_bad_command_line_sources_are_config_errors(spec, message, capsys):
    assert main(["run", "--source", spec, "--check"]) == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("where", ["build_parser", "_run"])
def test_ctrl_c_while_the_command_still_loads_is_exit_130_without_a_traceback(
    where: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """SIGINT 0.1-0.4 s into a command landed in its imports (parse, module load), outside the error funnel."""
    from rangebearing.cli import main as main_mod

    def interrupted(*_args: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(main_mod, where, interrupted)
    assert main_mod.main(["replay", "nowhere"]) == main_mod.EXIT_INTERRUPTED
    assert "Traceback" not in capsys.readouterr().err
