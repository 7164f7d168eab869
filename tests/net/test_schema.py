"""``schema/reading-v1.json`` describes what the encoder actually writes."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Dict

import pytest

import rangebearing.net.protocol as protocol
from rangebearing.cli.common import format_reading
from rangebearing.net.protocol import decode_reading, encode_reading

from .factories import make_landmark

SCHEMA_PATH = Path(protocol.__file__).resolve().parent.parent / "schema" / "reading-v1.json"


@pytest.fixture(scope="module")
def schema() -> Dict[str, Any]:
    return json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))


def test_schema_is_draft_2020_12_for_version_1(schema: Dict[str, Any]) -> None:
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert schema["properties"]["v"] == {"const": 1, "description": "Protocol version."}


def test_required_fields_match_the_encoder(schema: Dict[str, Any]) -> None:
    bare = json.loads(encode_reading("zumo", 1, 2.0))
    assert sorted(schema["required"]) == sorted(bare)
    assert list(schema["required"]) == list(protocol.READING_FIELDS)
    full = json.loads(encode_reading("zumo", 1, 2.0, [make_landmark()], fps=30.0, dropped=1, omitted=2))
    assert set(full) == set(schema["properties"])
    optional = set(schema["properties"]) - set(schema["required"])
    assert optional == set(protocol.OPTIONAL_FIELDS)


def test_landmark_columns_match_the_encoder(schema: Dict[str, Any]) -> None:
    columns = schema["properties"]["landmarks"]
    emitted = json.loads(encode_reading("zumo", 1, 2.0, [make_landmark()]))["landmarks"]
    assert list(columns["required"]) == list(protocol.LANDMARK_FIELDS)
    assert list(emitted) == list(protocol.LANDMARK_FIELDS + protocol.ADDED_FIELDS)
    assert set(columns["properties"]) == set(emitted)
    for name, spec in columns["properties"].items():
        assert spec["type"] == "array" and spec.get("description"), name


def test_full_validation_when_jsonschema_is_installed(schema: Dict[str, Any]) -> None:
    jsonschema = pytest.importorskip("jsonschema")
    validator = jsonschema.Draft202012Validator(schema)
    validator.check_schema(schema)
    for data in (encode_reading("zumo", 0, 1.0),
                 encode_reading("zumo", 1, 2.0, [make_landmark()] * 10, fps=30.0, dropped=4)):
        validator.validate(json.loads(data))
    bad = json.loads(encode_reading("zumo", 0, 1.0))
    bad["v"] = 2
    assert not validator.is_valid(bad)


def test_the_documented_example_is_a_valid_reading() -> None:
    doc = (Path(__file__).resolve().parents[2] / "docs" / "protocol.md").read_text("utf-8")
    block = doc.split("```json\n", 1)[1].split("```", 1)[0]
    data = "".join(line.strip() for line in block.splitlines()).encode()
    reading = decode_reading(data)
    assert f"({len(data)} bytes on the" in doc
    assert format_reading(reading) in doc
    assert reading.to_bytes() == data
