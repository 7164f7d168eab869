"""``schema/reading-v1.json`` and ``decode_reading`` accept exactly the same datagrams.

Generated from the schema itself (any column the schema gains is covered), then one
node replaced by a hostile value or removed: the decoder accepts a datagram if and
only if it is JSON text, valid under the schema, and its landmark columns have one
length (the single rule JSON Schema cannot state; the schema's description does).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Dict

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rangebearing.net.protocol as protocol
from rangebearing.errors import ProtocolError
from rangebearing.net.protocol import decode_reading

from . import schema_strategy as ss

jsonschema = pytest.importorskip("jsonschema")

SCHEMA: Dict[str, Any] = json.loads(
    (Path(protocol.__file__).resolve().parent.parent / "schema" / "reading-v1.json").read_text("utf-8"))
VALIDATOR = jsonschema.Draft202012Validator(SCHEMA)
DOCS = ss.from_schema(SCHEMA, SCHEMA).map(ss.same_length_columns)


def _not_json(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


def _schema_accepts(data: bytes) -> bool:
    try:
        doc = json.loads(data.decode("utf-8"), parse_constant=_not_json)
    except (UnicodeDecodeError, ValueError, RecursionError):
        return False  # not JSON text (NaN and Infinity are not JSON): outside what any schema can accept
    return VALIDATOR.is_valid(doc) and ss.columns_agree(doc)


def _decoder_accepts(data: bytes) -> bool:
    try:
        decode_reading(data)
    except ProtocolError:
        return False
    return True


@settings(max_examples=100, deadline=None)
@given(DOCS, st.booleans())
def test_every_datagram_the_schema_describes_is_decoded(doc: Dict[str, Any], ascii: bool) -> None:
    assert VALIDATOR.is_valid(doc), "the test strategy produced a document outside the schema"
    data = ss.to_bytes(doc, ascii)
    reading = decode_reading(data)
    assert (reading.robot, reading.seq, reading.t) == (doc["robot"], int(doc["seq"]), float(doc["t"]))
    assert len(reading.landmarks) == len(doc["landmarks"]["range_m"])


@settings(max_examples=300, deadline=None)
@given(DOCS, st.data(), st.booleans())
def test_schema_and_decoder_agree_one_mutation_away(doc: Dict[str, Any], data: st.DataObject, ascii: bool) -> None:
    path = data.draw(st.sampled_from(ss.paths(doc)))
    value = data.draw(st.sampled_from([*ss.HOSTILE, ss.DELETE]) if path else st.sampled_from(ss.HOSTILE))
    datagram = ss.to_bytes(ss.replaced(doc, path, value), ascii)
    assert _decoder_accepts(datagram) == _schema_accepts(datagram), (path, value, datagram[:300])


@pytest.mark.parametrize("text", [
    '"seq":5.0', '"seq":9007199254740991', '"t":1e308', '"t":-0.0', '"v":1.0',
    '"bearing_rad":[3.141592653589793]', '"bearing_rad":[-3.141592653589793]',
])
def test_edge_values_both_accept(text: str) -> None:
    data = _with(text)
    assert _schema_accepts(data) and _decoder_accepts(data)


@pytest.mark.parametrize("text", [
    '"seq":9007199254740992', '"seq":5.5', '"t":1e400', '"t":1' + '0' * 309, '"v":true',
    '"bearing_rad":[3.1415926535897936]', '"bearing_rad":[-3.1415926535897936]', '"robot":"\\ud800"',
    '"range_m":[-1e-300]', '"red_px":[[1,2,3]]',
])
def test_edge_values_both_refuse(text: str) -> None:
    data = _with(text)
    assert not _schema_accepts(data) and not _decoder_accepts(data)


def _with(text: str) -> bytes:
    """A valid one-landmark datagram with one field replaced by ``text`` (raw JSON)."""
    key, raw = text.split(":", 1)
    name = json.loads(key)
    doc = json.loads(protocol.encode_reading("zumo", 3, 7.0, [_landmark()]))
    marker = "\x00raw\x00"
    (doc["landmarks"] if name in doc["landmarks"] else doc)[name] = marker
    return json.dumps(doc).replace(json.dumps(marker), raw).encode()


def _landmark() -> Any:
    from .factories import make_landmark

    return make_landmark()
