"""sd_notify over a real AF_UNIX datagram socket standing in for systemd."""

from __future__ import annotations

import logging
import os
import socket
import sys
import time
import uuid
from pathlib import Path
from typing import Iterator, List, Tuple

import pytest

from rangebearing.daemon.sdnotify import Notifier, notify_address, watchdog_interval_s

pytestmark = pytest.mark.skipif(not hasattr(socket, "AF_UNIX"), reason="needs AF_UNIX")


@pytest.fixture
def systemd_socket(tmp_path: Path) -> Iterator[Tuple[socket.socket, str]]:
    """A bound datagram socket in tmp_path, as systemd's notify socket would be."""
    path = tmp_path / "notify"
    if len(str(path)) > 100:  # sun_path is 108 bytes
        pytest.skip("tmp_path too long for a unix socket path")
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind(str(path))
    sock.settimeout(2.0)  # a missing datagram fails the test instead of hanging
    yield sock, str(path)
    sock.close()


def received(sock: socket.socket) -> List[str]:
    return sock.recv(4096).decode("utf-8").split("\n")


def test_messages_arrive_as_newline_separated_fields(
    systemd_socket: Tuple[socket.socket, str],
) -> None:
    sock, path = systemd_socket
    with Notifier({"NOTIFY_SOCKET": path}) as n:
        assert n.enabled
        assert n.ready()
        assert received(sock) == ["READY=1"]
        assert n.ready("capturing 640x480")
        assert received(sock) == ["READY=1", "STATUS=capturing 640x480"]
        assert n.watchdog()
        assert received(sock) == ["WATCHDOG=1"]
        assert n.status("3 landmarks")
        assert received(sock) == ["STATUS=3 landmarks"]
        assert n.stopping()
        assert received(sock) == ["STOPPING=1"]
        assert (n.sent, n.failures) == (5, 0)


def test_reloading_sends_monotonic_usec_from_the_clock(
    systemd_socket: Tuple[socket.socket, str],
) -> None:
    sock, path = systemd_socket
    n = Notifier({"NOTIFY_SOCKET": path}, monotonic_ns=lambda: 123_456_789_999)
    assert n.reloading()
    assert received(sock) == ["RELOADING=1", "MONOTONIC_USEC=123456789"]
    n.close()


def test_reloading_uses_clock_monotonic_by_default(
    systemd_socket: Tuple[socket.socket, str],
) -> None:
    sock, path = systemd_socket
    n = Notifier({"NOTIFY_SOCKET": path})
    before = time_monotonic_usec()
    n.reloading()
    after = time_monotonic_usec()
    fields = received(sock)
    assert fields[0] == "RELOADING=1"
    key, _, value = fields[1].partition("=")
    assert key == "MONOTONIC_USEC"
    assert before <= int(value) <= after
    n.close()


def time_monotonic_usec() -> int:
    # systemd compares MONOTONIC_USEC with its own CLOCK_MONOTONIC reading.
    return time.clock_gettime_ns(time.CLOCK_MONOTONIC) // 1000


def test_status_cannot_inject_fields(systemd_socket: Tuple[socket.socket, str]) -> None:
    sock, path = systemd_socket
    n = Notifier({"NOTIFY_SOCKET": path})
    n.status("line one\nREADY=1")
    assert received(sock) == ["STATUS=line one READY=1"]
    n.close()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="abstract sockets are Linux-only")
def test_abstract_namespace_socket() -> None:
    name = f"rangebearing-test-{uuid.uuid4().hex}"
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind(b"\0" + name.encode())
    sock.settimeout(2.0)
    try:
        n = Notifier({"NOTIFY_SOCKET": "@" + name})
        assert n.ready()
        assert received(sock) == ["READY=1"]
        n.close()
    finally:
        sock.close()


def test_unset_notify_socket_does_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    def no_socket(*args: object, **kwargs: object) -> None:
        raise AssertionError("a socket was created without NOTIFY_SOCKET")

    monkeypatch.setattr(socket, "socket", no_socket)
    n = Notifier({})
    assert not n.enabled
    for call in (n.ready, n.watchdog, n.stopping, n.reloading):
        assert call() is False
    assert n.status("x") is False
    assert (n.sent, n.failures) == (0, 0)
    assert n.watchdog_interval_s() is None
    n.close()


def test_default_environment_is_os_environ(
    monkeypatch: pytest.MonkeyPatch, systemd_socket: Tuple[socket.socket, str]
) -> None:
    sock, path = systemd_socket
    monkeypatch.setenv("NOTIFY_SOCKET", path)
    n = Notifier()
    assert n.watchdog()
    assert received(sock) == ["WATCHDOG=1"]
    n.close()
    monkeypatch.delenv("NOTIFY_SOCKET")
    assert not Notifier().enabled


def test_send_failure_is_counted_not_raised(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    n = Notifier({"NOTIFY_SOCKET": str(tmp_path / "nobody-listens")})
    assert n.enabled
    with caplog.at_level(logging.DEBUG, logger="rangebearing.daemon.sdnotify"):
        assert n.ready() is False
        assert n.watchdog() is False
    assert (n.sent, n.failures) == (0, 2)
    warnings = [r for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1  # the first failure warns, repeats go to debug
    assert "READY=1" in warnings[0].getMessage()
    n.close()


def test_full_queue_drops_instead_of_blocking(systemd_socket: Tuple[socket.socket, str]) -> None:
    _sock, path = systemd_socket  # never read: the kernel queue fills up
    n = Notifier({"NOTIFY_SOCKET": path})
    for _ in range(5000):
        n.watchdog()
    assert n.sent > 0
    assert n.failures > 0
    assert n.sent + n.failures == 5000
    n.close()


def test_recovers_when_the_socket_appears_later(tmp_path: Path) -> None:
    path = tmp_path / "late"
    n = Notifier({"NOTIFY_SOCKET": str(path)})
    assert n.watchdog() is False
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind(str(path))
    sock.settimeout(2.0)
    try:
        assert n.watchdog() is True
        assert received(sock) == ["WATCHDOG=1"]
        assert (n.sent, n.failures) == (1, 1)
    finally:
        sock.close()
        n.close()


@pytest.mark.parametrize("value", ["relative/path", "@", "vsock:2:1234", "x"])
def test_unusable_notify_socket_disables(value: str, caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger="rangebearing.daemon.sdnotify"):
        n = Notifier({"NOTIFY_SOCKET": value})
    assert not n.enabled
    assert n.ready() is False
    assert n.failures == 0
    assert any("NOTIFY_SOCKET" in r.getMessage() for r in caplog.records)


def test_notify_address_forms() -> None:
    assert notify_address("/run/systemd/notify") == "/run/systemd/notify"
    assert notify_address("@abc") == b"\0abc"
    assert notify_address("") is None
    assert notify_address("@") is None


@pytest.mark.parametrize(
    ("env", "expected"),
    [
        ({"WATCHDOG_USEC": "10000000"}, 10.0),
        ({"WATCHDOG_USEC": "10000000", "WATCHDOG_PID": "4242"}, 10.0),
        ({"WATCHDOG_USEC": "10000000", "WATCHDOG_PID": "1"}, None),
        ({"WATCHDOG_USEC": "10000000", "WATCHDOG_PID": "abc"}, None),
        ({"WATCHDOG_USEC": "2500"}, 0.0025),
        ({"WATCHDOG_USEC": "0"}, None),
        ({"WATCHDOG_USEC": "-5"}, None),
        ({"WATCHDOG_USEC": "ten"}, None),
        ({"WATCHDOG_USEC": ""}, None),
        ({"WATCHDOG_PID": "4242"}, None),
        ({}, None),
    ],
)
def test_watchdog_interval_parsing(env: dict, expected: object) -> None:
    assert watchdog_interval_s(env, pid=4242) == expected
    assert Notifier(env, pid=4242).watchdog_interval_s() == expected


def test_watchdog_pid_defaults_to_this_process() -> None:
    env = {"WATCHDOG_USEC": "4000000", "WATCHDOG_PID": str(os.getpid())}
    assert Notifier(env).watchdog_interval_s() == 4.0
    env["WATCHDOG_PID"] = str(os.getpid() + 1)
    assert Notifier(env).watchdog_interval_s() is None
