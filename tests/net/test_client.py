"""The subscriber library over real loopback sockets."""

from __future__ import annotations

import socket
import time
from typing import Iterator

import pytest

from rangebearing.errors import SubscribeError
from rangebearing.net.client import Subscriber
from rangebearing.net.protocol import encode_reading

from .factories import make_landmark

GROUP = "239.255.47.80"


@pytest.fixture
def tx() -> Iterator[socket.socket]:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    yield s
    s.close()


def test_port_zero_exposes_the_bound_port() -> None:
    with Subscriber(port=0) as sub:
        assert sub.port > 0
        assert sub.address == ("127.0.0.1", sub.port)


def test_receives_a_reading_with_its_sender(tx: socket.socket) -> None:
    with Subscriber(port=0, timeout_s=2.0) as sub:
        tx.sendto(encode_reading("zumo", 3, 12.5, [make_landmark(bearing_rad=-0.07)]),
                  ("127.0.0.1", sub.port))
        r = sub.recv()
    assert r is not None and (r.robot, r.seq, r.t) == ("zumo", 3, 12.5)
    assert r.landmarks[0].bearing_rad == pytest.approx(-0.07)
    assert r.sender == ("127.0.0.1", tx.getsockname()[1])


def test_timeout_returns_none_quickly() -> None:
    with Subscriber(port=0) as sub:
        start = time.monotonic()
        assert sub.recv(timeout_s=0.05) is None
        assert time.monotonic() - start < 0.5
        assert sub.recv(timeout_s=0.0) is None


def test_garbage_is_dropped_counted_and_receiving_goes_on(tx: socket.socket) -> None:
    with Subscriber(port=0, timeout_s=2.0) as sub:
        dest = ("127.0.0.1", sub.port)
        for junk in (b"\x00\xff garbage", b'{"v":2,"robot":"future"}', b'{"hello":"world"}', b""):
            tx.sendto(junk, dest)
        tx.sendto(encode_reading("zumo", 1, 1.0), dest)
        tx.sendto(b"[[[", dest)
        tx.sendto(encode_reading("zumo", 2, 2.0), dest)
        first, second = sub.recv(), sub.recv()
        assert first is not None and first.seq == 1
        assert second is not None and second.seq == 2
        assert sub.dropped == 5 and sub.received == 2


def test_iteration_ends_cleanly_on_timeout(tx: socket.socket) -> None:
    with Subscriber(port=0, timeout_s=0.1) as sub:
        for seq in range(3):
            tx.sendto(encode_reading("zumo", seq, 1.0), ("127.0.0.1", sub.port))
        assert [r.seq for r in sub] == [0, 1, 2]
        tx.sendto(encode_reading("zumo", 7, 1.0), ("127.0.0.1", sub.port))
        assert [r.seq for r in sub.readings(timeout_s=0.1)] == [7]


def test_recv_datagram_returns_the_raw_bytes(tx: socket.socket) -> None:
    payload = encode_reading("zumo", 5, 1.0)
    with Subscriber(port=0, timeout_s=2.0) as sub:
        tx.sendto(payload, ("127.0.0.1", sub.port))
        got = sub.recv_datagram()
    assert got is not None and got[1] == payload and got[0].seq == 5


def test_multicast_group_reaches_two_subscribers_on_one_port(tx: socket.socket) -> None:
    tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
    tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    with Subscriber(port=0, group=GROUP, timeout_s=2.0) as a, \
            Subscriber(port=a.port, group=GROUP, timeout_s=2.0) as b:
        tx.sendto(encode_reading("zumo", 11, 1.0), (GROUP, a.port))
        ra, rb = a.recv(), b.recv()
    assert ra is not None and rb is not None and ra.seq == rb.seq == 11


def test_multicast_subscriber_ignores_unicast_to_its_port(tx: socket.socket) -> None:
    with Subscriber(port=0, group=GROUP, timeout_s=2.0) as sub:
        tx.sendto(encode_reading("zumo", 1, 1.0), ("127.0.0.1", sub.port))
        assert sub.recv(timeout_s=0.05) is None


@pytest.mark.parametrize("group", ["10.0.0.1", "not-an-address.invalid"])
def test_bad_group_is_a_config_error(group: str, monkeypatch: pytest.MonkeyPatch) -> None:
    def no_dns(host: str) -> str:
        if not host[:1].isdigit():
            raise socket.gaierror(socket.EAI_NONAME, "Name or service not known")
        return host

    monkeypatch.setattr(socket, "gethostbyname", no_dns)
    with pytest.raises(SubscribeError, match="group"):
        Subscriber(port=0, group=group)


def test_port_in_use_raises_oserror() -> None:
    with Subscriber(port=0) as a, pytest.raises(OSError):
        Subscriber(port=a.port)
