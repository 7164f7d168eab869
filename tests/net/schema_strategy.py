"""Hypothesis strategies for the JSON Schema subset ``reading-v1.json`` uses, and for
datagrams one mutation away from valid.

``hypothesis-jsonschema`` would do the first part, but its latest release (0.23.1)
fails on current Hypothesis (``'many' object has no attribute 'more'``). This walker
is small and strict: a keyword it does not know raises, so a schema that grows a new
kind of constraint cannot be silently half-tested.
"""

from __future__ import annotations

import json
import math
import re
import sys
from typing import Any, Dict, List

from hypothesis import strategies as st

from rangebearing.net import protocol

DBL_MAX = sys.float_info.max
_IGNORED = {"description", "title", "$schema", "$id", "$defs"}
_KNOWN = _IGNORED | {"$ref", "const", "type", "required", "properties", "items", "minItems", "maxItems",
                     "minimum", "maximum", "minLength", "maxLength", "pattern"}
MAX_COLUMN = 4  # entries per generated array: small datagrams, many of them


def _resolve(node: Dict[str, Any], root: Dict[str, Any]) -> Dict[str, Any]:
    node = dict(node)
    while "$ref" in node:
        ref = node.pop("$ref")
        if not ref.startswith("#/$defs/"):
            raise NotImplementedError(f"$ref {ref!r}")
        node = {**root["$defs"][ref.split("/")[-1]], **node}
    unknown = set(node) - _KNOWN
    if unknown:
        raise NotImplementedError(f"schema keyword(s) {sorted(unknown)} not handled by the test strategy")
    return node


def _numbers(node: Dict[str, Any], integer: bool) -> st.SearchStrategy[Any]:
    lo, hi = node.get("minimum", -DBL_MAX), node.get("maximum", DBL_MAX)
    ints = st.integers(min_value=math.ceil(lo), max_value=math.floor(hi))
    # JSON has one number type: an integer may arrive as 5.0, a number as 5 or as 1.7e308.
    whole = ints.filter(lambda i: abs(i) <= 2**53).map(float)
    if integer:
        return ints | whole
    return ints | st.floats(min_value=lo, max_value=hi, allow_nan=False, allow_infinity=False)


def from_schema(node: Dict[str, Any], root: Dict[str, Any]) -> st.SearchStrategy[Any]:
    """A strategy for JSON values valid under ``node`` (``root`` holds ``$defs``)."""
    node = _resolve(node, root)
    if "const" in node:
        return st.just(node["const"])
    kind = node["type"]
    if isinstance(kind, list):
        return st.one_of([from_schema({**node, "type": k}, root) for k in kind])
    if kind in ("number", "integer"):
        return _numbers(node, kind == "integer")
    if kind == "boolean":
        return st.booleans()
    if kind == "null":
        return st.none()
    if kind == "string":
        text = st.text(min_size=node.get("minLength", 0), max_size=node.get("maxLength", 12))
        if "pattern" in node:
            pattern = re.compile(node["pattern"])
            text = text.filter(lambda s: pattern.search(s) is not None)
        return text
    if kind == "array":
        items = from_schema(node["items"], root)
        most = min(node.get("maxItems", MAX_COLUMN), MAX_COLUMN)
        return st.lists(items, min_size=node.get("minItems", 0), max_size=most)
    if kind == "object":
        props = node.get("properties", {})
        required = set(node.get("required", ()))
        extra = st.dictionaries(st.text(max_size=6).filter(lambda k: k not in props), JSON_VALUES, max_size=2)
        fixed = st.fixed_dictionaries(
            {k: from_schema(v, root) for k, v in props.items() if k in required},
            optional={k: from_schema(v, root) for k, v in props.items() if k not in required},
        )
        return st.tuples(fixed, extra).map(lambda pair: {**pair[1], **pair[0]})
    raise NotImplementedError(f"type {kind!r}")


JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False, allow_infinity=False) | st.text(max_size=5),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=4), inner, max_size=3),
    max_leaves=6,
)


def same_length_columns(doc: Any) -> Any:
    """Cut every known landmark column to the shortest one's length (the one rule a schema cannot state)."""
    cols = doc.get("landmarks") if isinstance(doc, dict) else None
    if isinstance(cols, dict):
        known = [k for k in (protocol.LANDMARK_FIELDS + protocol.ADDED_FIELDS) if isinstance(cols.get(k), list)]
        n = min((len(cols[k]) for k in known), default=0)
        for k in known:
            cols[k] = cols[k][:n]
    return doc


def columns_agree(doc: Any) -> bool:
    cols = doc.get("landmarks") if isinstance(doc, dict) else None
    if not isinstance(cols, dict):
        return True
    names = protocol.LANDMARK_FIELDS + protocol.ADDED_FIELDS
    lengths = {len(cols[k]) for k in names if isinstance(cols.get(k), list)}
    return len(lengths) <= 1


# Values a hostile or careless writer puts where a valid one was; NOT_JSON_* become raw text.
NOT_JSON_INF, NOT_JSON_NAN = "\x00inf\x00", "\x00nan\x00"
HOSTILE: List[Any] = [
    0, -1, 5.0, 1.5, -0.0, 2**53 - 1, 2**53, 10**309, -(10**309), int(DBL_MAX), int(DBL_MAX) + 1, DBL_MAX,
    -DBL_MAX, math.pi, math.nextafter(math.pi, 4.0), -math.pi, math.nextafter(-math.pi, -4.0), 1e-320,
    True, False, None, "", "x", "\ud800", "a\udfffb", "\x1b[2J", "zumo\n#1 fake", "\u202e", [], [1.0, 2.0],
    [1.0], [[1.0, 2.0]], {}, {"v": 1}, NOT_JSON_INF, NOT_JSON_NAN, [[[[[]]]]],
]


def to_bytes(doc: Any, ascii: bool = True) -> bytes:
    """A datagram: ``doc`` as JSON, the NOT_JSON markers written ``1e400`` (parses as infinity)
    and ``NaN``; with ``ascii=False`` non-ASCII goes raw (a lone surrogate as invalid UTF-8)."""
    text = json.dumps(doc, ensure_ascii=ascii)
    for marker, raw in ((NOT_JSON_INF, "1e400"), (NOT_JSON_NAN, "NaN")):
        text = text.replace(json.dumps(marker, ensure_ascii=ascii), raw)
    return text.encode("utf-8", "surrogatepass")


def paths(doc: Any, prefix: tuple = ()) -> List[tuple]:
    """Every path (tuple of keys and indices) into ``doc``, the root included."""
    out = [prefix]
    if isinstance(doc, dict):
        for k, v in doc.items():
            out += paths(v, (*prefix, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            out += paths(v, (*prefix, i))
    return out


def replaced(doc: Any, path: tuple, value: Any) -> Any:
    """A copy of ``doc`` with the node at ``path`` replaced (``DELETE`` removes a key or an entry)."""
    if not path:
        return value
    copy = json.loads(json.dumps(doc))
    node = copy
    for key in path[:-1]:
        node = node[key]
    if value is DELETE:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return copy


DELETE = object()
