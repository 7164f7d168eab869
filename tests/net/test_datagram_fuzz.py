"""Datagram fuzzing: 21,000 generated and mutated datagrams through ``decode_reading``
and a real ``Subscriber`` on loopback. Nothing may raise outside ``ProtocolError``;
what is accepted can be printed safely and sent on again.

A seeded ``random.Random`` rather than Hypothesis: tens of thousands of cases in a
couple of seconds, the same ones on every run (a failure names its case number).
"""

from __future__ import annotations

import functools
import json
import random
import re
import socket
from typing import Iterator, List

import pytest

from rangebearing.cli.common import format_reading
from rangebearing.errors import ProtocolError
from rangebearing.net.client import Subscriber
from rangebearing.net.protocol import MAX_DATAGRAM_BYTES, RemoteLandmark, decode_reading, encode_reading

N_CASES = 21_000
NUMBER = re.compile(rb"-?\d+(?:\.\d+)?(?:[eE][+-]?\d+)?")
STRING = re.compile(rb'"(?:[^"\\]|\\.)*"')
HOSTILE_NUMBERS = [b"1e400", b"-1e400", b"1" + b"0" * 309, b"-1" + b"0" * 309, b"9" * 4301, b"NaN", b"Infinity",
                   b"-Infinity", b"-0", b"5.0", b"1.5", b"9007199254740992", b"3.1415926535897936", b"1e-400",
                   b"true", b"null", b"[]", b"{}", b'"5"', b"[1,2,3]", b"0x10", b"01", b"1.", b".5", b"+1"]
HOSTILE_STRINGS = [b'"\\ud800"', b'"\\udfff\\ud800"', b'""', b'"\\u0000"', b'"\x1b[2J"', b'"a\\nb"', b'"\xff"',
                   b'"\xed\xa0\x80"', b'"\xc2\x9b"', b'"\\u202e"', b"1", b"null", b'"' + b"x" * 3000 + b'"']


def _landmark(rng: random.Random) -> RemoteLandmark:
    r = rng.uniform(0.05, 5.0)
    return RemoteLandmark(r, rng.uniform(-3.14, 3.14), rng.random() < 0.8, rng.uniform(0, 500),
                          r * 0.9, rng.uniform(-2, 2), (rng.uniform(0, 1280), rng.uniform(0, 960)),
                          (rng.uniform(0, 1280), rng.uniform(0, 960)), rng.uniform(0, 200))


def _valid(rng: random.Random) -> bytes:
    robot = rng.choice(["zumo-07", "r", "zumo-é", "x" * 40, "\u7a7a\u6a5f"])
    return encode_reading(robot, rng.randrange(2**40), rng.uniform(0, 2e9),
                          [_landmark(rng) for _ in range(rng.randrange(6))],
                          fps=rng.choice([None, 29.97]), dropped=rng.choice([None, 0, 12]))


def _replace_match(rng: random.Random, data: bytes, pattern: re.Pattern, choices: List[bytes]) -> bytes:
    m = pattern.search(data, rng.randrange(len(data))) or pattern.search(data)
    if m is None:
        return data
    return data[: m.start()] + rng.choice(choices) + data[m.end():]


def _mutate(rng: random.Random, data: bytes, other: bytes) -> bytes:
    kind = rng.randrange(9)
    i = rng.randrange(len(data))
    if kind == 0:  # flip bits in one byte
        return data[:i] + bytes([data[i] ^ (1 << rng.randrange(8))]) + data[i + 1:]
    if kind == 1:  # insert random bytes
        return data[:i] + bytes(rng.randrange(256) for _ in range(rng.randrange(1, 5))) + data[i:]
    if kind == 2:  # cut a span out
        return data[:i] + data[i + rng.randrange(1, 40):]
    if kind == 3:  # truncate
        return data[:i]
    if kind == 4:  # splice with another datagram
        return data[:i] + other[rng.randrange(len(other)):]
    if kind == 5:
        return _replace_match(rng, data, NUMBER, HOSTILE_NUMBERS)
    if kind == 6:
        return _replace_match(rng, data, STRING, HOSTILE_STRINGS)
    if kind == 7:  # wrap a value in deep nesting
        depth = rng.choice([10, 1000, 20000])
        return _replace_match(rng, data, NUMBER, [b"[" * depth + b"1" + b"]" * depth])
    # a structural change, re-serialised (when earlier mutations left JSON to change)
    try:
        msg = json.loads(data)
    except (ValueError, RecursionError):
        return data[::-1]
    if not isinstance(msg, dict) or not msg:
        return data
    key = rng.choice(list(msg))
    msg[key] = rng.choice([None, [], {}, "x", 1.5, -1, {"range_m": [1]}, [msg.get(key)]])
    return json.dumps(msg).encode()


@functools.lru_cache(maxsize=1)
def cases() -> List[bytes]:
    """The datagrams, the same on every run: 1 in 8 valid as sent, the rest mutated one to five times."""
    rng = random.Random(20261201)
    pool = [_valid(rng) for _ in range(400)]
    out = []
    for n in range(N_CASES):
        data = rng.choice(pool)
        if n % 8:
            other = rng.choice(pool)
            for _ in range(rng.randrange(1, 6)):
                data = _mutate(rng, data, other) or b"{"
        out.append(data)
    return out


def test_decode_raises_nothing_but_protocol_error() -> None:
    accepted = 0
    for n, data in enumerate(cases()):
        try:
            reading = decode_reading(data)
        except ProtocolError as exc:
            assert len(str(exc)) < 300, (n, str(exc)[:400])
            continue
        except Exception as exc:  # the point of the test: name any escapee and its case
            pytest.fail(f"case {n}: {type(exc).__name__}: {exc!s:.200} for {data[:200]!r}")
        accepted += 1
        assert format_reading(reading).isprintable(), n
        assert decode_reading(reading.to_bytes()).robot == reading.robot, n  # what is accepted can be sent on
    assert len(cases()) >= 20_000
    assert N_CASES // 8 <= accepted < N_CASES  # both branches are exercised


def _batches(datagrams: List[bytes], max_count: int = 32, max_bytes: int = 80_000) -> Iterator[List[bytes]]:
    """Small batches: a batch never overflows the subscriber's receive buffer."""
    batch: List[bytes] = []
    size = 0
    for data in datagrams:
        if batch and (len(batch) == max_count or size + len(data) > max_bytes):
            yield batch
            batch, size = [], 0
        batch.append(data)
        size += len(data)
    if batch:
        yield batch


def test_subscriber_drops_and_counts_every_bad_datagram_and_keeps_receiving() -> None:
    sendable = [d for d in cases() if 0 < len(d) <= MAX_DATAGRAM_BYTES]
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    n_batches = 0
    with Subscriber(port=0) as sub:
        dest = ("127.0.0.1", sub.port)
        for n_batches, batch in enumerate(_batches(sendable), 1):
            for data in batch:
                tx.sendto(data, dest)
            tx.sendto(encode_reading("end-of-batch", n_batches, 1.0), dest)
            while True:  # iterate until this batch's end marker: every datagram before it was consumed
                reading = next(iter(sub.readings(timeout_s=2.0)), None)
                assert reading is not None, f"batch {n_batches}: the subscriber stopped receiving"
                if reading.robot == "end-of-batch" and reading.seq == n_batches:
                    break
    tx.close()
    assert sub.received + sub.dropped == len(sendable) + n_batches
    assert sub.dropped > len(sendable) // 2
