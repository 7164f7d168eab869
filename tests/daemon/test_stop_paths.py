"""A stop (SIGTERM) that lands while the daemon opens, reopens or swaps its source ends the run with 0, and a
recording that cannot be opened is never waited for. Deterministic: the stop is requested from inside the
opener at the moment in question, no timing involved."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import List

import pytest

from rangebearing.cli.run_cmd import source_opener
from rangebearing.config import load_config
from rangebearing.daemon.loop import Daemon
from rangebearing.errors import CameraError, CameraLibraryError
from rangebearing.net.publisher import MemoryPublisher
from tests.daemon.test_loop import RecordingNotifier, opener, recorded_cfg


def reload_at_second_frame(daemon: Daemon, cfg_file: Path, new_config: str) -> List[int]:
    """After the second datagram the config file becomes ``new_config`` and a reload is asked for; a stop
    after the sixth. Returns the datagram counter (``[n]``)."""
    n = [0]

    def echo(payload: bytes) -> None:
        n[0] += 1
        if n[0] == 2:
            cfg_file.write_text(new_config)
            daemon.request_reload()
        elif n[0] == 6:
            daemon.stop()

    daemon.echo = echo
    return n


def test_a_stop_while_the_camera_is_still_missing_at_start_exits_0(static_clip: Path) -> None:
    calls: List[int] = []
    daemon: Daemon

    def missing(cfg, sleep):
        calls.append(1)
        if len(calls) == 2:
            daemon.stop()  # SIGTERM during the open's back-off
        raise CameraError("camera 0: not found")

    pub = MemoryPublisher()
    daemon = Daemon(recorded_cfg(static_clip), missing, lambda c: pub, RecordingNotifier())
    assert daemon.run() == 0
    assert len(calls) == 2 and pub.payloads == [] and pub.closed


def test_a_stop_during_a_reloads_source_swap_exits_0_without_reopening_for_long(static_clip: Path,
                                                                                tmp_path: Path) -> None:
    cfg_file = tmp_path / "c.yaml"
    cfg_file.write_text(f'source: {{kind: recorded, path: "{static_clip}", fps: 0, loop: true}}\n')
    opened: List[str] = []
    daemon: Daemon

    def open_source(cfg, sleep):
        opened.append(cfg.source.kind)
        if cfg.source.kind == "picamera2":  # the new config's camera: SIGTERM lands while it is retried
            daemon.stop()
            raise CameraError("camera 0: busy")
        return opener(cfg, sleep)

    pubs: List[MemoryPublisher] = []

    def open_pub(c):
        pubs.append(MemoryPublisher())
        return pubs[-1]

    daemon = Daemon(load_config(cfg_file), open_source, open_pub, RecordingNotifier(),
                    reload=lambda: load_config(cfg_file))
    sent: List[bytes] = []

    def echo(payload: bytes) -> None:
        sent.append(payload)
        if len(sent) == 3:
            cfg_file.write_text("source: {kind: picamera2}\n")
            daemon.request_reload()

    daemon.echo = echo
    assert daemon.run() == 0
    assert len(sent) == 3 and opened == ["recorded", "picamera2"]  # the old source was not reopened for a stop
    assert all(p.closed for p in pubs)


def test_a_reload_to_a_recording_that_cannot_open_is_rejected_at_once(static_clip: Path, tmp_path: Path,
                                                                      caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="rangebearing.daemon")
    cfg_file = tmp_path / "c.yaml"
    good = f'source: {{kind: recorded, path: "{static_clip}", fps: 0, loop: true}}\n'
    cfg_file.write_text(good)
    daemon = Daemon(load_config(cfg_file), source_opener, lambda c: MemoryPublisher(), RecordingNotifier(),
                    reload=lambda: load_config(cfg_file))
    n = reload_at_second_frame(daemon, cfg_file,
                               f'source: {{kind: recorded, path: "{tmp_path / "gone"}", fps: 0, loop: true}}\n')
    assert daemon.run() == 0
    assert n[0] == 6  # frames went on from the old recording
    assert "reload rejected: cannot open the new frame source" in caplog.text
    assert "retrying" not in caplog.text  # a path that is not there does not appear by waiting


def test_a_reload_to_a_camera_whose_library_is_missing_keeps_the_running_source(static_clip: Path, tmp_path: Path,
                                                                                 caplog: pytest.LogCaptureFixture
                                                                                 ) -> None:
    cfg_file = tmp_path / "c.yaml"
    cfg_file.write_text(f'source: {{kind: recorded, path: "{static_clip}", fps: 0, loop: true}}\n')

    def open_source(cfg, sleep):
        if cfg.source.kind == "picamera2":  # no picamera2 on this machine: not retried, and not fatal on a reload
            raise CameraLibraryError("cannot import picamera2 (No module named 'picamera2')")
        return opener(cfg, sleep)

    daemon = Daemon(load_config(cfg_file), open_source, lambda c: MemoryPublisher(), RecordingNotifier(),
                    reload=lambda: load_config(cfg_file))
    n = reload_at_second_frame(daemon, cfg_file, "source: {kind: picamera2}\n")
    assert daemon.run() == 0 and n[0] == 6
    assert "reload rejected: cannot open the new frame source" in caplog.text
