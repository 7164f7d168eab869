"""FIFOs, pipes and sockets where a file is expected: a clear error at once, never a process that hangs.

``open()`` of a FIFO blocks until the other end opens it, and ``rangebearing run`` keeps SIGTERM for
itself, so before these checks ``run --config FIFO`` (or ``--record FIFO``) neither started nor stopped.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from rangebearing.config.file_bytes import read_bounded
from rangebearing.errors import SourceError
from rangebearing.sources.recorded import RecordedSource

TIMEOUT_S = 60.0  # a loaded machine: what happened is asserted, not how fast


def rangebearing(*argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "rangebearing.cli.main", *argv], stdin=subprocess.DEVNULL,
                          capture_output=True,
                          text=True, timeout=TIMEOUT_S, env={**os.environ, "RANGEBEARING_CACHE": "off"})


@pytest.fixture
def fifo(tmp_path: Path) -> Path:
    path = tmp_path / "config.yaml"
    os.mkfifo(path)
    return path


def test_a_config_fifo_without_a_writer_is_an_empty_file_at_once(fifo: Path) -> None:
    done = rangebearing("run", "--check", "--config", str(fifo))
    assert done.returncode == 2, done.stderr
    assert "the file is empty" in done.stderr and "Traceback" not in done.stderr


def test_a_config_piped_in_is_read_whole(tmp_path: Path) -> None:
    proc = subprocess.Popen([sys.executable, "-m", "rangebearing.cli.main", "run", "--check", "--config",
                             "/dev/stdin"], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    try:
        out, err = proc.communicate("source: {fps: 12}\n", timeout=TIMEOUT_S)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert "/dev/stdin: OK" in out


def _opened(path: Path) -> int:
    """How many of this process's descriptors are open on ``path``."""
    count = 0
    for fd in os.listdir("/proc/self/fd"):
        try:
            count += os.readlink(f"/proc/self/fd/{fd}") == str(path)
        except OSError:
            continue
    return count


def test_a_fifo_whose_writer_sends_in_pieces_is_read_to_its_end(fifo: Path) -> None:
    writer = os.open(fifo, os.O_RDWR)  # a writer end that is there before the reader (Linux: no wait)
    got: list = []
    try:
        os.write(writer, b"source:")
        reader = threading.Thread(target=lambda: got.append(read_bounded(fifo, 1000, wait_s=TIMEOUT_S)))
        reader.start()
        deadline = time.monotonic() + TIMEOUT_S
        while _opened(fifo) < 2 and time.monotonic() < deadline:  # the reader has its end (else data is lost)
            time.sleep(0.005)
        os.write(writer, b" {fps: 12}\n")
    finally:
        os.close(writer)  # the end of the stream
    reader.join(TIMEOUT_S)
    assert got == [b"source: {fps: 12}\n"]


def test_a_writer_that_never_ends_is_a_timeout_not_a_hang(tmp_path: Path) -> None:
    r, w = os.pipe()
    try:
        os.write(w, b"source: {fps: 12}\n")  # and the write end stays open
        with pytest.raises(TimeoutError, match="never closes"):
            read_bounded(f"/proc/self/fd/{r}", 1000, wait_s=0.2)
    finally:
        os.close(r)
        os.close(w)


def test_a_huge_device_is_read_only_to_the_limit() -> None:
    assert len(read_bounded("/dev/zero", 1000)) == 1001


def test_a_fifo_or_socket_is_no_recording(fifo: Path, tmp_path: Path) -> None:
    with pytest.raises(SourceError, match="a FIFO, not a recording"):
        RecordedSource(fifo).open()
    sock_path = tmp_path / "s"
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as sock:
        sock.bind(str(sock_path))
        with pytest.raises(SourceError, match="a socket, not a recording"):
            RecordedSource(sock_path).open()
    done = rangebearing("replay", str(fifo))
    assert done.returncode == 1 and "a FIFO, not a recording" in done.stderr, done.stderr


def test_recording_into_a_fifo_is_refused_at_once(tmp_path: Path, static_clip: Path) -> None:
    target = tmp_path / "rec.mcap"
    os.mkfifo(target)
    done = rangebearing("run", "--source", str(static_clip), "--fps", "0", "--record", str(target))
    assert done.returncode == 1, done.stderr
    assert "a FIFO or socket, not a file to record into" in done.stderr and "Traceback" not in done.stderr


def test_a_truth_fifo_is_refused_at_once(fifo: Path, static_clip: Path) -> None:
    done = rangebearing("replay", str(static_clip), "--truth", str(fifo))
    assert done.returncode == 1, done.stderr
    assert "not a regular file" in done.stderr and "Traceback" not in done.stderr
