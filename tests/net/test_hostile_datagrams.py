"""Datagrams from a hostile network: each is dropped and counted, and every consumer
(``decode_reading``, the ``Subscriber``, ``listen`` in both modes) carries on."""

from __future__ import annotations

import io
import json
import socket
from typing import Iterator

import pytest

from rangebearing.cli import listen_cmd
from rangebearing.errors import ProtocolError
from rangebearing.net.client import Subscriber
from rangebearing.net.protocol import Reading, decode_reading, encode_reading

from .factories import make_landmark

HUGE_T = b'{"v":1,"robot":"x","seq":0,"t":1' + b"0" * 309 + b',"landmarks":{}}'  # the repro
COLS = json.loads(encode_reading("r", 0, 1.0))["landmarks"]


def _doc(**fields: object) -> bytes:
    doc = {"v": 1, "robot": "zumo", "seq": 1, "t": 2.0, "landmarks": COLS, **fields}
    return json.dumps(doc).encode()


def _column(name: str, raw: str) -> bytes:
    """A valid one-landmark datagram whose column ``name`` holds ``raw`` (JSON text) instead."""
    doc = json.loads(encode_reading("z", 1, 2.0, [make_landmark()]))
    doc["landmarks"][name] = ["\x00mark\x00"]
    return json.dumps(doc).replace('"\\u0000mark\\u0000"', raw).encode()


HOSTILE = {
    "10**309 in t": HUGE_T,
    "10**309 in fps": _doc().replace(b'"t": 2.0', b'"t": 2.0, "fps": 1' + b"0" * 309),
    "-10**309 in t": _doc().replace(b'"t": 2.0', b'"t": -1' + b"0" * 400),
    "5000-digit seq": _doc().replace(b'"seq": 1', b'"seq": 1' + b"0" * 5000),
    "10**309 in a landmark": _column("d_v_m", "1" + "0" * 309),
    "1e400 in a landmark": _column("range_m", "1e400"),
    "NaN in a landmark": _column("l_px", "NaN"),
    "-Infinity bearing": _column("bearing_rad", "-Infinity"),
    "bearing just above pi": _column("bearing_rad", "3.1415926535897936"),
    "point of huge ints": _column("red_px", "[1" + "0" * 400 + ", 2]"),
    "lone surrogate robot": _doc(robot="\ud800"),
    "lone low surrogate robot": _doc(robot="a\udc00"),
    "dropped 2**53": _doc(dropped=2**53),
    "deep nesting": b'{"v":1,"robot":"x","seq":0,"t":0,"landmarks":' + b"[" * 30000 + b"]" * 30000 + b"}",
    "deep object nesting": b'{"a":' * 10000 + b"1" + b"}" * 10000,
    "invalid UTF-8": _doc().replace(b"zumo", b"zu\xffmo"),
    "CESU surrogate bytes": _doc().replace(b"zumo", b"zu\xed\xa0\x80mo"),
}


@pytest.mark.parametrize("data", HOSTILE.values(), ids=list(HOSTILE))
def test_decode_raises_only_protocol_error_with_a_short_message(data: bytes) -> None:
    with pytest.raises(ProtocolError) as info:
        decode_reading(data)
    assert type(info.value) is ProtocolError and len(str(info.value)) < 200


def test_integers_written_as_whole_floats_are_integers() -> None:
    r = decode_reading(_doc(seq=5.0, dropped=2.0, v=1.0))
    assert r.seq == 5 and isinstance(r.seq, int) and r.dropped == 2


@pytest.fixture
def tx() -> Iterator[socket.socket]:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    yield s
    s.close()


@pytest.mark.parametrize("as_json", [False, True])
def test_listen_survives_every_hostile_datagram(tx: socket.socket, as_json: bool) -> None:
    raw = io.BytesIO()
    out = io.TextIOWrapper(raw, encoding="utf-8", errors="strict")  # a lone surrogate would raise here
    sendable = [d for d in HOSTILE.values() if len(d) < 65000]
    with Subscriber(port=0) as sub:
        for data in sendable:
            tx.sendto(data, ("127.0.0.1", sub.port))
        tx.sendto(encode_reading("after", 9, 3.0), ("127.0.0.1", sub.port))
        assert listen_cmd.echo(sub, out, as_json=as_json, count=1, timeout_s=2.0) == 0
        assert sub.dropped == len(sendable) and sub.received == 1
    out.flush()
    text = raw.getvalue().decode()
    assert text.count("\n") == 1 and "after" in text


NASTY_IDS = {
    "zumo\n#1 t=0.000  0 landmarks": "zumo\\x0a#1 t=0.000  0 landmarks",
    "\x1b[2J\x1b[31mred": "\\x1b[2J\\x1b[31mred",
    "evil\u202egnp.exe": "evil\\u202egnp.exe",
    "c1\x9bcsi": "c1\\x9bcsi",
    "back\\slash": "back\\\\slash",
    "tab\there": "tab\\x09here",
    "\ud800": "\\ud800",
    "zumo-07": "zumo-07",
    "zumo-é": "zumo-é",
}


@pytest.mark.parametrize("robot", NASTY_IDS, ids=[ascii(k) for k in NASTY_IDS])
def test_listen_shows_control_characters_escaped(robot: str) -> None:
    line = listen_cmd.format_reading(Reading(robot, 1, 0.0))
    assert line == f"{NASTY_IDS[robot]} #1 t=0.000  0 landmarks"
    assert line.isprintable()


def test_listen_delivers_a_received_nasty_id_escaped(tx: socket.socket) -> None:
    out = io.StringIO()
    with Subscriber(port=0) as sub:
        tx.sendto(encode_reading("a\nb\x1b[0m", 1, 2.0), ("127.0.0.1", sub.port))
        # A raw C1 control (valid JSON, valid UTF-8) in --json mode comes out as a \u escape.
        tx.sendto(_doc(robot="c1\x9b").replace(b"\\u009b", "\x9b".encode()), ("127.0.0.1", sub.port))
        assert listen_cmd.echo(sub, out, count=1, timeout_s=2.0) == 0
        assert listen_cmd.echo(sub, out, as_json=True, count=1, timeout_s=2.0) == 0
    first, second = out.getvalue().splitlines()
    assert first.startswith("a\\x0ab\\x1b[0m #1 ")
    assert second.isascii() and second.isprintable() and "c1\\u009b" in second
