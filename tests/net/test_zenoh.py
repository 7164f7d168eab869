"""Readings over Zenoh on loopback: the payload, the counters, presence, faults that never escape."""

from __future__ import annotations

import json
import logging
import queue
import subprocess
import sys
import time

import pytest
import zenoh

from rangebearing.errors import ConfigError, MissingExtraError
from rangebearing.net.protocol import Reading, RemoteLandmark, encode_reading
from rangebearing.net.zenoh_client import ZenohSubscriber
from rangebearing.net.zenoh_transport import (
    ZenohPublisher,
    ZenohSettings,
    presence_key,
    reading_key,
)

from .zenoh_helpers import free_tcp_port, hub, spoke

LM = RemoteLandmark(0.5, 0.1, True, 40.0, 0.03, 0.0, (300.0, 200.0), (300.0, 240.0), 12.0)


def payload(robot: str, seq: int) -> bytes:
    return encode_reading(robot, seq, 1_700_000_000.0 + seq, [LM], fps=15.0, dropped=0)


def first_reading(pub: ZenohPublisher, sub: ZenohSubscriber, robot: str, wait_s: float = 5.0) -> Reading:
    """Send until the subscriber hears one (declarations take a moment to meet after connecting)."""
    deadline = time.monotonic() + wait_s
    seq = 0
    while time.monotonic() < deadline:
        pub.send(payload(robot, seq))
        got = sub.recv(0.05)
        if got is not None:
            return got
        seq += 1
    raise AssertionError("no reading arrived over Zenoh")


def wait_presence(sub: ZenohSubscriber, robot: str, alive: bool, wait_s: float = 5.0) -> None:
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline:
        ev = sub.recv_presence(0.1)
        if ev is not None and ev.robot == robot and ev.alive == alive:
            assert (robot in sub.alive) == alive
            return
    raise AssertionError(f"no presence event {robot} alive={alive}")


@pytest.fixture
def port() -> int:
    return free_tcp_port()


def test_settings_become_zenoh_config_without_listening_everywhere() -> None:
    doc = json.loads(ZenohSettings(connect=("tcp/10.0.0.1:7447",), scouting_multicast=False).to_json5())
    assert doc == {"mode": "peer", "connect": {"endpoints": ["tcp/10.0.0.1:7447"]},
                   "scouting": {"multicast": {"enabled": False}}}  # empty listen: Zenoh's default
    cfg = ZenohSettings(listen=("tcp/127.0.0.1:7447",)).zenoh_config()
    assert json.loads(cfg.get_json("listen/endpoints")) == ["tcp/127.0.0.1:7447"]


def test_bad_settings_name_every_problem() -> None:
    bad = ZenohSettings(mode="router", connect=("192.168.1.10:7447",), listen=("tcp/",))
    with pytest.raises(ConfigError) as err:
        bad.zenoh_config()
    text = str(err.value)
    assert "publish.zenoh.mode" in text and "connect[0]" in text and "listen[0]" in text
    assert "client mode needs" in str(ZenohSettings(mode="client").problems())


def test_keys() -> None:
    assert reading_key("rangebearing/{robot}/readings", "zumo3") == "rangebearing/zumo3/readings"
    assert presence_key("rangebearing/*/readings") == "rangebearing/*/alive"
    with pytest.raises(ConfigError, match="key chunk"):
        ZenohPublisher("a/b", hub(1))


def test_reading_arrives_as_the_exact_udp_bytes_with_json_encoding(port: int) -> None:
    raw: queue.Queue = queue.Queue()
    with ZenohSubscriber(settings=hub(port)) as sub, ZenohPublisher("zumo1", spoke(port)) as pub:
        first = first_reading(pub, sub, "zumo1")
        assert first.robot == "zumo1" and first.landmarks == (LM,)
        spy = zenoh.open(spoke(port).zenoh_config())
        try:
            spy.declare_subscriber("rangebearing/**", lambda s: raw.put((str(s.encoding), s.payload.to_bytes())))
            sent = payload("zumo1", 99)
            deadline = time.monotonic() + 5
            while raw.empty() and time.monotonic() < deadline:
                pub.send(sent)
                time.sleep(0.02)
            encoding, data = raw.get(timeout=1)
        finally:
            spy.close()
        assert encoding == "application/json"
        assert data == sent  # one schema, one decoder: the UDP datagram itself
        assert pub.stats.sent >= 2 and pub.stats.total_errors == 0


def test_invalid_payloads_are_dropped_and_counted(port: int) -> None:
    with ZenohSubscriber(settings=hub(port), timeout_s=0.5) as sub, ZenohPublisher("zumo1", spoke(port)) as pub:
        first_reading(pub, sub, "zumo1")
        while sub.recv(0.5) is not None:  # first_reading's earlier sends still on their way (a loaded machine)
            pass
        # Puts use CongestionControl.DROP, so a loaded machine may lose a sample on the way: each junk payload is
        # sent (with a valid one behind it) until the subscriber has counted it; none may ever come out as a reading.
        for seq, junk in enumerate((b"not json", b'{"v": 2}', b"[]"), start=7):
            dropped, sent, deadline = sub.dropped, 0, time.monotonic() + 20.0
            while sub.dropped == dropped and time.monotonic() < deadline:
                before, sent = sub.received, sent + 1
                pub.send(junk)
                pub.send(payload("zumo1", seq))
                got = sub.recv(2.0)
                assert got is None or got.seq <= seq  # a valid payload (perhaps a late one); the junk never decodes
                assert sub.received == before + (got is not None)
            assert dropped < sub.dropped <= dropped + sent, f"{junk!r} was never counted as dropped"


def test_a_key_for_one_robot_hears_only_that_robot(port: int) -> None:
    with ZenohSubscriber("rangebearing/zumo2/readings", hub(port)) as sub, \
            ZenohPublisher("zumo1", spoke(port)) as one, ZenohPublisher("zumo2", spoke(port)) as two:
        assert first_reading(two, sub, "zumo2").robot == "zumo2"
        for seq in range(20):
            one.send(payload("zumo1", seq))
        two.send(payload("zumo2", 1000))
        robots = {r.robot for r in sub.readings(timeout_s=0.5)}
        assert robots == {"zumo2"}
        assert sub.alive == {"zumo2"}  # presence follows the same key


def test_liveliness_token_appears_and_disappears(port: int) -> None:
    with ZenohSubscriber(settings=hub(port)) as sub:
        pub = ZenohPublisher("zumo7", spoke(port))
        wait_presence(sub, "zumo7", alive=True)
        pub.close()
        wait_presence(sub, "zumo7", alive=False)
        pub.send(payload("zumo7", 1))  # after close: nothing, and no error
        assert pub.stats.total_errors == 0


def test_a_broken_session_is_counted_logged_and_reopened(port: int, caplog: pytest.LogCaptureFixture) -> None:
    with ZenohSubscriber(settings=hub(port)) as sub, ZenohPublisher("zumo1", spoke(port)) as pub:
        first_reading(pub, sub, "zumo1")
        wait_presence(sub, "zumo1", alive=True)
        pub._session.close()  # the session dies under the publisher
        with caplog.at_level(logging.WARNING):
            for seq in range(5):
                pub.send(payload("zumo1", seq))  # never raises
        assert pub.stats.errors.get("put", 0) + pub.stats.errors.get("no-session", 0) == 5
        assert sum("zenoh put" in r.message for r in caplog.records) == 1  # rate-limited
        wait_presence(sub, "zumo1", alive=False)
        assert pub.wait_connected(5.0)
        wait_presence(sub, "zumo1", alive=True)  # a new session, a new token
        assert first_reading(pub, sub, "zumo1").robot == "zumo1"


def test_client_without_a_router_never_raises_into_send(port: int) -> None:
    settings = ZenohSettings(mode="client", connect=(f"tcp/127.0.0.1:{port}",), scouting_multicast=False)
    pub = ZenohPublisher("zumo1", settings, wait_s=0.3, retry_interval_s=0.05)
    try:
        for seq in range(3):
            pub.send(payload("zumo1", seq))
        stats = pub.stats
        assert not stats.connected and stats.sent == 0
        assert stats.errors["no-session"] == 3 and stats.errors["open"] >= 1
        # The router comes up: the publisher finds it on its own.
        with ZenohSubscriber(settings=hub(port)) as sub:
            assert pub.wait_connected(5.0)
            assert first_reading(pub, sub, "zumo1").robot == "zumo1"
    finally:
        pub.close()


def test_missing_zenoh_is_a_clear_import_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "zenoh", None)
    with pytest.raises(MissingExtraError, match=r"pip install 'rangebearing\[zenoh\]'") as err:
        ZenohSubscriber()
    assert isinstance(err.value, ImportError)


def test_a_process_that_never_closes_its_subscriber_still_exits(port: int) -> None:
    script = (
        "from rangebearing.net.zenoh_client import ZenohSubscriber\n"
        "from rangebearing.net.zenoh_transport import ZenohSettings\n"
        f"sub = ZenohSubscriber(settings=ZenohSettings(listen=('tcp/127.0.0.1:{port}',), scouting_multicast=False))\n"
        "print('ready', flush=True)\n"
        "print(sub.recv_presence(10).robot, flush=True)\n"  # callbacks have run: their threads exist
    )
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout is not None and child.stdout.readline().strip() == "ready"
        with ZenohPublisher("zumo5", spoke(port)):
            assert child.stdout.readline().strip() == "zumo5"
            assert child.wait(timeout=10) == 0  # no hang joining Zenoh's callback threads
    finally:
        child.kill()


def test_clients_meet_through_a_router(port: int) -> None:
    """The zenohd layout: robots and controller in client mode, a router in between (here zenoh's own, in-process)."""
    router_cfg = zenoh.Config.from_json5(json.dumps({
        "mode": "router", "listen": {"endpoints": [f"tcp/127.0.0.1:{port}"]},
        "scouting": {"multicast": {"enabled": False}}}))
    client = ZenohSettings(mode="client", connect=(f"tcp/127.0.0.1:{port}",), scouting_multicast=False)
    router = zenoh.open(router_cfg)
    try:
        with ZenohSubscriber(settings=client) as sub, ZenohPublisher("zumo4", client) as pub:
            assert first_reading(pub, sub, "zumo4").robot == "zumo4"
            wait_presence(sub, "zumo4", alive=True)  # liveliness goes through the router too
            pub.close()
            wait_presence(sub, "zumo4", alive=False)
    finally:
        router.close()
