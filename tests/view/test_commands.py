"""``rangebearing view`` and ``run`` with ``daemon.view_port`` as processes; bad options fail clearly."""

from __future__ import annotations

import json
import socket
import urllib.request
from pathlib import Path

import pytest

from rangebearing.cli.main import main
from tests.view.processes import Served

REPO = Path(__file__).resolve().parents[2]


def get_json(url: str) -> dict:
    with urllib.request.urlopen(url, timeout=10) as r:
        return json.loads(r.read())


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_the_daemon_serves_the_view_when_configured(tmp_path: Path, static_clip: Path) -> None:
    port = free_port()
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f'source: {{kind: recorded, path: "{static_clip}", fps: 30, loop: true}}\n'
        'publish: {unicast: ["127.0.0.1:47898"]}\n'
        f"daemon: {{view_port: {port}}}\n"
    )
    served = Served(["run", "--config", str(cfg)])
    try:
        assert served.url == f"http://127.0.0.1:{port}/"
        state = get_json(served.url + "api/state")
        assert len(state["landmarks"]) == 2 and state["config_file"] == str(cfg)
    finally:
        assert served.stop() == 0


def test_view_command_on_the_bundled_clip() -> None:
    served = Served(["view", "--config", str(REPO / "config" / "demo.yaml"), "--loop", "--port", "0"])
    try:
        state = get_json(served.url + "api/state")
        assert len(state["landmarks"]) == 2 and state["frame"]["name"].endswith(".jpg")
    finally:
        assert served.stop() == 0


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["view", "--port", "70000"], "--port: 70000"),
        (["view", "--view-fps", "0"], "--view-fps: 0"),
    ],
)
def test_bad_options(argv: list, words: str, capsys: pytest.CaptureFixture) -> None:
    assert main([*argv, "--source", str(REPO / "samples" / "clip")]) == 2
    assert words in capsys.readouterr().err


def test_bad_view_config(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    cfg = tmp_path / "c.yaml"
    cfg.write_text("daemon: {view_port: 99999, view_fps: 0}\n")
    assert main(["run", "--config", str(cfg), "--check"]) == 2
    err = capsys.readouterr().err
    assert "daemon.view_port" in err and "daemon.view_fps" in err
