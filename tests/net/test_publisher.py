"""Publishers over real loopback sockets: delivery, fault counting, rate-limited logs."""

from __future__ import annotations

import logging
import socket
from typing import Any, Dict, Iterator, List

import pytest

from rangebearing.config import PublishConfig
from rangebearing.net.client import Subscriber
from rangebearing.net.protocol import encode_reading
from rangebearing.net.publisher import MemoryPublisher, Publisher, UdpPublisher

from .factories import make_landmark

GROUP = "239.255.47.80"


@pytest.fixture
def sub() -> Iterator[Subscriber]:
    with Subscriber(port=0, timeout_s=2.0) as s:
        yield s


def _dead_port() -> int:
    """A loopback port nobody listens on (bound, noted, closed)."""
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = int(s.getsockname()[1])
    s.close()
    return port


def _cfg(*ports: int, **kw: Any) -> PublishConfig:
    return PublishConfig(unicast=tuple(("127.0.0.1", p) for p in ports), **kw)


def test_publisher_to_subscriber(sub: Subscriber) -> None:
    payload = encode_reading("zumo", 42, 1000.5, [make_landmark()], fps=30.0)
    with UdpPublisher(_cfg(sub.port)) as pub:
        pub.send(payload)
        stats = pub.stats
    r = sub.recv()
    assert r is not None and r.robot == "zumo" and r.seq == 42
    assert r.landmarks[0].range_m == pytest.approx(0.412)
    assert r.sender is not None and r.sender[0] == "127.0.0.1"
    assert stats.sent == {f"127.0.0.1:{sub.port}": 1} and stats.total_errors == 0


def test_every_unicast_destination_gets_every_payload() -> None:
    with Subscriber(port=0, timeout_s=2.0) as a, Subscriber(port=0, timeout_s=2.0) as b:
        cfg = PublishConfig(unicast=(("127.0.0.1", a.port), ("localhost", b.port)))
        with UdpPublisher(cfg) as pub:
            assert pub.destinations == (f"127.0.0.1:{a.port}", f"localhost:{b.port}")
            for seq in range(3):
                pub.send(encode_reading("zumo", seq, 1.0))
        for s in (a, b):
            got = [s.recv() for _ in range(3)]
            assert [r.seq for r in got if r is not None] == [0, 1, 2]


def test_duplicate_destinations_are_sent_once(sub: Subscriber) -> None:
    with UdpPublisher(_cfg(sub.port, sub.port)) as pub:
        assert len(pub.destinations) == 1


def test_dead_destination_never_raises_is_counted_and_spares_the_live_one(
    sub: Subscriber,
) -> None:
    dead = _dead_port()
    name = f"127.0.0.1:{dead}"
    with UdpPublisher(_cfg(dead, sub.port)) as pub:
        n = 0
        # ICMP port-unreachable comes back asynchronously and surfaces on a
        # later send; keep sending until it has, rather than sleeping.
        while n < 200 and not pub.stats.errors:
            pub.send(encode_reading("zumo", n, 1.0))
            n += 1
        stats = pub.stats
    assert stats.errors.get(name, {}).get("ECONNREFUSED", 0) >= 1
    assert stats.sent[name] + sum(stats.errors[name].values()) == n
    assert stats.sent[f"127.0.0.1:{sub.port}"] == n
    assert [sub.recv() is not None for _ in range(n)] == [True] * n


def test_oversized_payload_is_counted_not_raised(sub: Subscriber) -> None:
    with UdpPublisher(_cfg(sub.port)) as pub:
        pub.send(b"x" * 70000)
        pub.send(encode_reading("zumo", 1, 1.0))
        stats = pub.stats
    assert stats.errors == {f"127.0.0.1:{sub.port}": {"EMSGSIZE": 1}}
    assert stats.total_sent == 1
    r = sub.recv()
    assert r is not None and r.seq == 1


def test_faults_are_logged_at_a_limited_rate(caplog: pytest.LogCaptureFixture,
                                             sub: Subscriber) -> None:
    now = [100.0]
    log = logging.getLogger("test.publisher")
    with caplog.at_level(logging.WARNING, logger="test.publisher"), \
            UdpPublisher(_cfg(sub.port), logger=log, clock=lambda: now[0]) as pub:
        for _ in range(5):
            pub.send(b"x" * 70000)  # EMSGSIZE every time
        assert len(caplog.records) == 1
        now[0] += 9.9
        pub.send(b"x" * 70000)
        assert len(caplog.records) == 1
        now[0] += 0.2
        pub.send(b"x" * 70000)
        assert pub.stats.errors[f"127.0.0.1:{sub.port}"]["EMSGSIZE"] == 7
    messages = [r.getMessage() for r in caplog.records]
    assert len(messages) == 2
    assert "EMSGSIZE" in messages[0] and f"127.0.0.1:{sub.port}" in messages[0]
    assert "5 more errors" in messages[1]


def test_multicast_through_loopback() -> None:
    with Subscriber(port=0, group=GROUP, interface="127.0.0.1", timeout_s=2.0) as s:
        cfg = PublishConfig(unicast=(), multicast_group=GROUP, multicast_port=s.port,
                            multicast_ttl=0, multicast_interface="127.0.0.1")
        with UdpPublisher(cfg) as pub:
            pub.send(encode_reading("zumo", 9, 1.0, [make_landmark()]))
            assert pub.stats.sent == {f"{GROUP}:{s.port}": 1}
        r = s.recv()
    assert r is not None and r.seq == 9 and len(r.landmarks) == 1
    assert r.sender is not None and r.sender[0] == "127.0.0.1"  # left through lo


def _fake_dns(monkeypatch: pytest.MonkeyPatch, failures: Dict[str, List[int]]) -> None:
    """Names in ``failures`` fail with the listed EAI codes in turn, then resolve to 127.0.0.1
    (no name ever reaches a real resolver: the test sends no DNS query)."""
    real = socket.getaddrinfo

    def fake(host: str, port: Any, *args: Any, **kw: Any) -> List[Any]:
        if host in failures:
            if failures[host]:
                code = failures[host].pop(0)
                raise socket.gaierror(code, "Temporary failure in name resolution" if code == socket.EAI_AGAIN
                                      else "Name or service not known")
            host = "127.0.0.1"
        return real(host, port, *args, **kw)

    monkeypatch.setattr(socket, "getaddrinfo", fake)


def test_an_unresolvable_host_does_not_stop_the_others(monkeypatch: pytest.MonkeyPatch, sub: Subscriber,
                                                       caplog: pytest.LogCaptureFixture) -> None:
    _fake_dns(monkeypatch, {"no-such-robot.invalid": [socket.EAI_NONAME] * 1000})
    cfg = PublishConfig(unicast=(("no-such-robot.invalid", 47800), ("127.0.0.1", sub.port)))
    with caplog.at_level(logging.WARNING), UdpPublisher(cfg, retry_s=0.01, max_retry_s=0.02) as pub:
        assert len(pub.pending) == 1 and "no-such-robot.invalid" in pub.pending[0]
        for seq in range(3):
            pub.send(encode_reading("zumo", seq, 1.0))
        stats = pub.stats
    assert stats.sent[f"127.0.0.1:{sub.port}"] == 3
    assert stats.errors == {"no-such-robot.invalid:47800": {"UNRESOLVED": 3}}
    assert [r.seq for r in (sub.recv(), sub.recv(), sub.recv()) if r] == [0, 1, 2]
    warnings = [r.getMessage() for r in caplog.records if "no-such-robot" in r.getMessage()]
    assert len(warnings) == 1 and "retrying" in warnings[0]  # said once, not at every retry


def test_dns_down_at_boot_is_retried_until_it_resolves(monkeypatch: pytest.MonkeyPatch,
                                                       sub: Subscriber) -> None:
    _fake_dns(monkeypatch, {"base-station.lan": [socket.EAI_AGAIN] * 3})
    cfg = PublishConfig(unicast=(("base-station.lan", sub.port),))
    with UdpPublisher(cfg, retry_s=0.01, max_retry_s=0.05) as pub:
        assert pub.pending  # the only destination: the publisher starts anyway
        pub.send(encode_reading("zumo", 0, 1.0))  # counted, not raised
        seq = 1
        while pub.pending and seq < 500:
            sub.recv(timeout_s=0.01)
            seq += 1
        assert not pub.pending
        pub.send(encode_reading("zumo", seq, 1.0))
        stats = pub.stats
    assert stats.errors[f"base-station.lan:{sub.port}"] == {"UNRESOLVED": 1}
    r = sub.recv()
    assert r is not None and r.seq == seq


def test_multicast_interface_that_is_not_local_is_pending_not_fatal() -> None:
    cfg = PublishConfig(unicast=(), multicast_group=GROUP, multicast_interface="192.0.2.1")
    with UdpPublisher(cfg, retry_s=10.0) as pub:
        assert len(pub.pending) == 1 and "multicast_interface" in pub.pending[0]
        pub.send(encode_reading("zumo", 0, 1.0))
        assert pub.stats.errors == {f"{GROUP}:47800": {"UNRESOLVED": 1}}


def test_close_stops_the_retries_promptly(monkeypatch: pytest.MonkeyPatch) -> None:
    _fake_dns(monkeypatch, {"never.invalid": [socket.EAI_NONAME] * 10**6})
    pub = UdpPublisher(PublishConfig(unicast=(("never.invalid", 1),)), retry_s=0.01, max_retry_s=0.01)
    retrier = pub._retrier
    assert retrier is not None and retrier.is_alive()
    pub.close()
    retrier.join(timeout=2.0)
    assert not retrier.is_alive()


def test_send_after_close_is_a_no_op(sub: Subscriber) -> None:
    pub = UdpPublisher(_cfg(sub.port))
    pub.close()
    pub.close()
    pub.send(encode_reading("zumo", 1, 1.0))
    assert pub.stats.total_sent == 0 and pub.stats.total_errors == 0
    assert sub.recv(timeout_s=0.05) is None


def test_memory_publisher_keeps_payloads() -> None:
    pub: Publisher = MemoryPublisher()
    pub.send(b"a")
    pub.send(bytearray(b"b"))
    pub.close()
    assert isinstance(pub, MemoryPublisher)
    assert pub.payloads == [b"a", b"b"] and pub.closed
