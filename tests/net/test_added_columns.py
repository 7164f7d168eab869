"""The columns added to wire format v1: sigmas, visible, track id and rates."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any, Dict

import pytest

import rangebearing.net.protocol as protocol
from rangebearing.cli.common import describe
from rangebearing.errors import ProtocolError
from rangebearing.net.protocol import ADDED_FIELDS, LANDMARK_FIELDS, decode_reading, encode_reading

from .factories import make_landmark

SCHEMA = json.loads((Path(protocol.__file__).resolve().parent.parent / "schema" / "reading-v1.json").read_text())


def _tracked(**kw: Any):
    values: Dict[str, Any] = dict(range_sigma_m=0.00234, bearing_sigma_rad=0.000456, visible=0.8123, track_id=7,
                                  range_rate_mps=-0.12345, bearing_rate_radps=0.54321)
    values.update(kw)
    return dataclasses.replace(make_landmark(), **values)


def test_round_trip_with_the_added_columns():
    data = encode_reading("zumo", 3, 10.0, [_tracked(), _tracked(track_id=8, range_rate_mps=None,
                                                                bearing_rate_radps=None)])
    cols = json.loads(data)["landmarks"]
    assert list(cols) == list(LANDMARK_FIELDS + ADDED_FIELDS)
    assert cols["range_sigma_m"] == [0.0023, 0.0023] and cols["bearing_sigma_rad"] == [0.00046, 0.00046]
    assert cols["visible"] == [0.81, 0.81] and cols["track_id"] == [7, 8]
    assert cols["range_rate_mps"] == [-0.123, None] and cols["bearing_rate_radps"] == [0.5432, None]
    assert b"null" in data
    a, b = decode_reading(data).landmarks
    assert (a.range_sigma_m, a.bearing_sigma_rad, a.visible, a.track_id) == (0.0023, 0.00046, 0.81, 7)
    assert (a.range_rate_mps, a.bearing_rate_radps) == (-0.123, 0.5432)
    assert b.track_id == 8 and b.range_rate_mps is None and b.bearing_rate_radps is None
    assert decode_reading(data).to_bytes() == data


def test_a_datagram_without_the_added_columns_still_decodes():
    msg = json.loads(encode_reading("zumo", 3, 10.0, [_tracked()]))
    for name in ADDED_FIELDS:
        del msg["landmarks"][name]
    old = json.dumps(msg, separators=(",", ":")).encode()
    lm = decode_reading(old).landmarks[0]
    assert lm.range_m == 0.412 and lm.track_id is None and lm.range_sigma_m is None and lm.visible is None
    assert decode_reading(old).to_bytes() == old  # nothing invented on the way back
    assert describe(lm) == "0.412 m  +12.3°"


def test_an_older_reader_finds_its_columns_unchanged():
    new = json.loads(encode_reading("zumo", 3, 10.0, [_tracked()]))["landmarks"]
    plain = json.loads(encode_reading("zumo", 3, 10.0, [make_landmark()]))["landmarks"]
    assert {k: new[k] for k in LANDMARK_FIELDS} == {k: plain[k] for k in LANDMARK_FIELDS}
    assert set(new) - set(LANDMARK_FIELDS) == set(ADDED_FIELDS)


def test_an_untracked_landmark_says_so_and_a_tiny_sigma_is_not_rounded_to_zero():
    cols = json.loads(encode_reading("z", 0, 0.0, [_tracked(track_id=-1, range_sigma_m=1e-7,
                                                             bearing_sigma_rad=0.0)]))["landmarks"]
    assert cols["track_id"] == [-1] and cols["range_sigma_m"] == [0.0001] and cols["bearing_sigma_rad"] == [0.0]


@pytest.mark.parametrize("change", [{"visible": 1.5}, {"visible": -0.1}, {"range_sigma_m": -0.01},
                                    {"bearing_sigma_rad": math.nan}, {"track_id": -2}, {"track_id": 1.5},
                                    {"track_id": True}, {"range_rate_mps": math.inf},
                                    {"bearing_rate_radps": math.nan}])
def test_the_encoder_refuses_bad_added_values(change):
    with pytest.raises(ProtocolError):
        encode_reading("z", 0, 0.0, [_tracked(**change)])


@pytest.mark.parametrize("column, value", [("visible", 1.01), ("visible", "1"), ("range_sigma_m", -1.0),
                                           ("bearing_sigma_rad", None), ("track_id", -2), ("track_id", 1.5),
                                           ("track_id", True), ("track_id", None), ("range_rate_mps", "fast"),
                                           ("bearing_rate_radps", True)])
def test_the_decoder_refuses_bad_added_values(column, value):
    msg = json.loads(encode_reading("z", 0, 0.0, [_tracked()]))
    msg["landmarks"][column] = [value]
    with pytest.raises(ProtocolError, match=column):
        decode_reading(json.dumps(msg).encode())


def test_an_added_column_of_the_wrong_length_is_refused():
    msg = json.loads(encode_reading("z", 0, 0.0, [_tracked(), _tracked()]))
    msg["landmarks"]["track_id"] = [1]
    with pytest.raises(ProtocolError, match="track_id"):
        decode_reading(json.dumps(msg).encode())


def test_the_schema_validates_the_added_columns():
    jsonschema = pytest.importorskip("jsonschema")
    validator = jsonschema.Draft202012Validator(SCHEMA)
    good = json.loads(encode_reading("z", 0, 0.0, [_tracked(), _tracked(range_rate_mps=None)]))
    validator.validate(good)
    legacy = json.loads(encode_reading("z", 0, 0.0, [_tracked()]))
    for name in ADDED_FIELDS:
        del legacy["landmarks"][name]
    validator.validate(legacy)
    for column, value in (("visible", 1.2), ("track_id", -3), ("track_id", 0.5), ("range_sigma_m", -0.1),
                          ("range_rate_mps", "x")):
        bad = json.loads(json.dumps(good))
        bad["landmarks"][column][0] = value
        assert not validator.is_valid(bad), column


def test_a_describe_line_carries_id_sigma_and_rates():
    line = describe(_tracked())
    assert line.startswith("id 7: ") and "±2.3 mm" in line and "-0.123 m/s" in line and "81 % visible" in line
    assert "°/s" in line
