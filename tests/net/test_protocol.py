"""Wire format v1: round trips, the size bound, and strict rejection."""

from __future__ import annotations

import copy
import json
import math
from typing import Any, Callable, Dict

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rangebearing.core.types import Landmark
from rangebearing.errors import ProtocolError, RangeBearingError
from rangebearing.net.fit import MTU_PAYLOAD_BYTES
from rangebearing.net.protocol import (
    ADDED_FIELDS,
    LANDMARK_FIELDS,
    Reading,
    RemoteLandmark,
    decode_reading,
    encode_reading,
)

from .factories import make_landmark


def test_encode_known_values_by_hand() -> None:
    lm = make_landmark(range_m=0.41234567, bearing_rad=-0.0698132)
    data = encode_reading("zumo", 1234, 1732419876.25, [lm], fps=29.971, dropped=3)
    msg = json.loads(data)
    assert msg["v"] == 1 and msg["robot"] == "zumo" and msg["seq"] == 1234
    assert msg["t"] == 1732419876.25
    cols = msg["landmarks"]
    assert cols["range_m"] == [0.4123]  # 0.1 mm
    assert cols["bearing_rad"] == [-0.06981]  # 1e-5 rad
    assert cols["in_envelope"] == [True]
    assert cols["red_px"] == [[250.25, 120.5]] and cols["blue_px"] == [[251.25, 205.06]]
    assert msg["fps"] == 29.97 and msg["dropped"] == 3
    assert b" " not in data  # compact separators


def test_heartbeat_has_every_column_empty_and_no_stats() -> None:
    msg = json.loads(encode_reading("zumo", 0, 1.5, []))
    assert msg["landmarks"] == {name: [] for name in LANDMARK_FIELDS + ADDED_FIELDS}
    assert "fps" not in msg and "dropped" not in msg
    assert decode_reading(encode_reading("zumo", 0, 1.5)) == Reading("zumo", 0, 1.5)


def test_eight_landmarks_with_every_column_fit_one_mtu() -> None:
    # Long-winded values on purpose: 4-digit pixels, many decimals, negative signs, 6-digit ids.
    # Eight is the crowd of issue 8 (5-8 robots in view); more are IP-fragmented (docs/protocol.md).
    lms = [
        Landmark(12.345678, -0.1234567, 12.098765, -1.5432109, 1234.5678,
                 (1279.987654, 959.123456), (1278.55555, 958.44444), 123.456789,
                 (1200, 900, 79, 59), i % 2 == 0, range_sigma_m=0.123456, bearing_sigma_rad=0.0123456,
                 visible=0.8765, track_id=123456, range_rate_mps=-1.23456, bearing_rate_radps=-1.234567)
        for i in range(8)
    ]
    data = encode_reading("zumo-swarm-07", 2**40, 1732419876.123456, lms, fps=29.97,
                          dropped=123456)
    assert len(decode_reading(data).landmarks) == 8
    assert len(data) <= MTU_PAYLOAD_BYTES, len(data)


def test_sender_is_attached_and_not_encoded() -> None:
    data = encode_reading("zumo", 1, 2.0)
    r = decode_reading(data, sender=("127.0.0.1", 5000))
    assert r.sender == ("127.0.0.1", 5000)
    assert r.to_bytes() == data


def test_negative_zero_is_written_as_zero() -> None:
    lm = make_landmark(bearing_rad=-1e-9)
    assert json.loads(encode_reading("z", 0, 0.0, [lm]))["landmarks"]["bearing_rad"] == [0.0]
    assert b"-0.0" not in encode_reading("z", 0, 0.0, [lm])


def test_numpy_scalars_are_accepted() -> None:
    lm = Landmark(np.float32(0.5), np.float64(0.1), np.float32(0.49), np.float32(0.05),
                  np.float32(80.0), (np.float32(1.0), np.float32(2.0)), (3.0, 4.0),
                  np.float32(10.0), (0, 0, 1, 1), np.bool_(False))
    r = decode_reading(encode_reading("z", np.int64(7), np.float64(3.0), [lm], dropped=np.int64(2)))
    assert r.seq == 7 and r.dropped == 2
    assert r.landmarks[0].range_m == 0.5 and r.landmarks[0].in_envelope is False


@pytest.mark.parametrize(
    "kwargs",
    [
        {"robot": ""},
        {"robot": 5},
        {"robot": "\ud800"},
        {"seq": 2**53},
        {"t": 10**400},
        {"seq": -1},
        {"seq": 1.5},
        {"seq": True},
        {"t": math.nan},
        {"fps": math.inf},
        {"dropped": -2},
        {"landmarks": [make_landmark(range_m=math.nan)]},
    ],
)
def test_encoder_rejects_unrepresentable_values(kwargs: Dict[str, Any]) -> None:
    args: Dict[str, Any] = {"robot": "zumo", "seq": 1, "t": 1.0, "landmarks": ()}
    args.update(kwargs)
    with pytest.raises(ProtocolError):
        encode_reading(**args)


# --- round trip (hypothesis) -------------------------------------------------

finite = st.floats(min_value=-1e5, max_value=1e5, allow_nan=False, allow_infinity=False)
size = st.floats(min_value=0.0, max_value=1e5, allow_nan=False, allow_infinity=False)
landmarks = st.builds(
    RemoteLandmark,
    range_m=size,
    bearing_rad=st.floats(min_value=-3.14, max_value=3.14),
    in_envelope=st.booleans(),
    l_px=size,
    d_v_m=finite,
    d_h_m=finite,
    red_xy_px=st.tuples(finite, finite),
    blue_xy_px=st.tuples(finite, finite),
    width_px=size,
)
readings = st.builds(
    Reading,
    robot=st.text(min_size=1, max_size=20),
    seq=st.integers(min_value=0, max_value=2**53 - 1),
    t=st.floats(min_value=0.0, max_value=4e9),
    landmarks=st.lists(landmarks, max_size=12).map(tuple),
    fps=st.none() | st.floats(min_value=0.0, max_value=1000.0),
    dropped=st.none() | st.integers(min_value=0, max_value=2**31),
)


def _close(a: float, b: float, digits: int) -> bool:
    return abs(a - b) <= 0.5 * 10.0**-digits + 4 * math.ulp(b)


@given(readings)
def test_round_trip_within_rounding(r: Reading) -> None:
    data = r.to_bytes()
    back = decode_reading(data)
    assert (back.robot, back.seq, back.dropped) == (r.robot, r.seq, r.dropped)
    assert _close(back.t, r.t, 6)
    assert (back.fps is None) == (r.fps is None)
    if r.fps is not None:
        assert back.fps is not None and _close(back.fps, r.fps, 2)
    assert len(back.landmarks) == len(r.landmarks)
    for got, want in zip(back.landmarks, r.landmarks):
        assert got.in_envelope == want.in_envelope
        for name, digits in (("range_m", 4), ("d_v_m", 4), ("d_h_m", 4), ("bearing_rad", 5),
                             ("l_px", 2), ("width_px", 2)):
            assert _close(getattr(got, name), getattr(want, name), digits), name
        for g, w in zip(got.red_xy_px + got.blue_xy_px, want.red_xy_px + want.blue_xy_px):
            assert _close(g, w, 2)
    # Rounding is idempotent: re-encoding a decoded reading changes nothing.
    assert back.to_bytes() == data


# --- strict decoding -----------------------------------------------------------


def _valid() -> Dict[str, Any]:
    return json.loads(encode_reading("zumo", 5, 100.0, [make_landmark()], fps=30.0, dropped=0))


def _mutated(change: Callable[[Dict[str, Any]], Any]) -> bytes:
    msg = copy.deepcopy(_valid())
    change(msg)
    return json.dumps(msg).encode()


MALFORMED = {
    "empty": b"",
    "not utf-8": b"\xff\xfe\x00{",
    "not json": b"hello robots",
    "json array": b"[1, 2, 3]",
    "json string": b'"v"',
    "foreign object": b'{"temperature": 21.5}',
    "nan literal": b'{"v":1,"robot":"z","seq":1,"t":NaN,"landmarks":{}}',
    "deep nesting": b"[" * 50000 + b"]" * 50000,
    "too big": b" " * 70000,
    "version 2": _mutated(lambda m: m.update(v=2)),
    "version 0": _mutated(lambda m: m.update(v=0)),
    "version as string": _mutated(lambda m: m.update(v="1")),
    "version 1.5": _mutated(lambda m: m.update(v=1.5)),
    "version as bool": _mutated(lambda m: m.update(v=True)),
    "no robot": _mutated(lambda m: m.pop("robot")),
    "empty robot": _mutated(lambda m: m.update(robot="")),
    "numeric robot": _mutated(lambda m: m.update(robot=7)),
    "no seq": _mutated(lambda m: m.pop("seq")),
    "negative seq": _mutated(lambda m: m.update(seq=-1)),
    "float seq": _mutated(lambda m: m.update(seq=1.5)),
    "no t": _mutated(lambda m: m.pop("t")),
    "string t": _mutated(lambda m: m.update(t="now")),
    "overflowing t": _mutated(lambda m: m.update(t=1e308)).replace(b"1e+308", b"1e999"),
    "no landmarks": _mutated(lambda m: m.pop("landmarks")),
    "landmarks as list of objects": _mutated(lambda m: m.update(landmarks=[{"range_m": 1.0}])),
    "missing column": _mutated(lambda m: m["landmarks"].pop("width_px")),
    "column not a list": _mutated(lambda m: m["landmarks"].update(range_m=1.0)),
    "ragged columns": _mutated(lambda m: m["landmarks"]["range_m"].append(1.0)),
    "negative range": _mutated(lambda m: m["landmarks"].update(range_m=[-0.5])),
    "bearing beyond pi": _mutated(lambda m: m["landmarks"].update(bearing_rad=[4.0])),
    "envelope as int": _mutated(lambda m: m["landmarks"].update(in_envelope=[1])),
    "range as bool": _mutated(lambda m: m["landmarks"].update(range_m=[True])),
    "point too short": _mutated(lambda m: m["landmarks"].update(red_px=[[1.0]])),
    "point too long": _mutated(lambda m: m["landmarks"].update(blue_px=[[1.0, 2.0, 3.0]])),
    "point of strings": _mutated(lambda m: m["landmarks"].update(red_px=[["1", "2"]])),
    "negative fps": _mutated(lambda m: m.update(fps=-1.0)),
    "null fps": _mutated(lambda m: m.update(fps=None)),
    "float dropped": _mutated(lambda m: m.update(dropped=0.5)),
}


@pytest.mark.parametrize("data", MALFORMED.values(), ids=list(MALFORMED))
def test_malformed_foreign_or_other_version_is_rejected(data: bytes) -> None:
    with pytest.raises(ProtocolError) as info:
        decode_reading(data)
    assert isinstance(info.value, (RangeBearingError, ValueError))
    assert str(info.value)


def test_version_error_names_the_version() -> None:
    with pytest.raises(ProtocolError, match="version 2"):
        decode_reading(_mutated(lambda m: m.update(v=2)))


def test_unknown_extra_fields_are_ignored() -> None:
    def add(m: Dict[str, Any]) -> None:
        m["battery_v"] = 7.4
        m["pose"] = {"x": 1}
        m["landmarks"]["colour"] = ["red"]

    r = decode_reading(_mutated(add))
    assert r.robot == "zumo" and len(r.landmarks) == 1
    assert r == decode_reading(json.dumps(_valid()).encode())


def test_integers_are_accepted_where_numbers_are_expected() -> None:
    r = decode_reading(_mutated(lambda m: m.update(t=100, fps=30)))
    assert r.t == 100.0 and isinstance(r.t, float) and r.fps == 30.0


_FINITE = st.floats(allow_nan=False, allow_infinity=False, width=64)
_ANY = st.one_of(_FINITE, st.sampled_from([math.nan, math.inf, -math.inf, -0.0, 0.0, 1e-9, math.pi, -math.pi]),
                 st.integers(-3, 3), st.none())


@given(st.lists(st.tuples(*[_ANY] * 15, st.one_of(st.integers(-2, 10**6), st.booleans(), st.none()),
                          st.booleans()), min_size=1, max_size=3))
def test_the_fast_row_is_byte_for_byte_the_checked_encoding(values: Any) -> None:
    """Whatever the numbers, the frame-rate path writes exactly what the checked path writes, or defers to it."""
    from rangebearing.net import protocol

    lms = []
    for v in values:
        lms.append(RemoteLandmark(range_m=v[0], bearing_rad=v[1], in_envelope=v[16], l_px=v[2], d_v_m=v[3],
                                  d_h_m=v[4], red_xy_px=(v[5], v[6]), blue_xy_px=(v[7], v[8]), width_px=v[9],
                                  range_sigma_m=v[10], bearing_sigma_rad=v[11], visible=v[12], track_id=v[15],
                                  range_rate_mps=v[13], bearing_rate_radps=v[14]))
    for lm in lms:
        row = protocol._row(lm)
        if row is None:
            continue  # the checked path decides (and raises for what cannot be sent)
        checked = protocol.landmark_fields(lm)
        assert json.dumps(dict(zip(protocol._COLUMNS, row))) == json.dumps(checked)


def test_numpy_numbers_take_the_fast_row_and_encode_as_floats() -> None:
    from rangebearing.net import protocol

    lm = make_landmark(range_m=np.float64(0.41234567), bearing_rad=np.float32(-0.0698132))
    assert protocol._row(lm) is not None
    assert json.dumps(dict(zip(protocol._COLUMNS, protocol._row(lm)))) == json.dumps(protocol.landmark_fields(lm))
