"""The colour thresholds the view page can change live: hue ranges, saturation and value minimums."""

from __future__ import annotations

import dataclasses
from typing import Any, Dict, Mapping, Tuple, TypeVar

from .._compat import frozen
from ..errors import RequestError

HueRanges = Tuple[Tuple[int, int], ...]
D = TypeVar("D")

KEYS = ("red_hue", "blue_hue", "s_min", "v_min")
MAX_RANGES = 4  # red needs two (it wraps around hue 0); more is a typo, not a colour


@frozen
class Thresholds:
    """The detection keys a browser may set. Hue follows OpenCV's 0-179; S and V are 0-255."""

    red_hue: HueRanges
    blue_hue: HueRanges
    s_min: int
    v_min: int

    @classmethod
    def of(cls, detection: Any) -> Thresholds:
        """The thresholds of detection parameters (any object with the four attributes)."""
        return cls(
            tuple(map(tuple, detection.red_hue)), tuple(map(tuple, detection.blue_hue)),
            int(detection.s_min), int(detection.v_min),
        )

    def apply(self, detection: D) -> D:
        """A copy of the detection parameters (a frozen dataclass) with these thresholds."""
        return dataclasses.replace(detection, **self.as_dict())  # type: ignore[type-var]

    def as_dict(self) -> Dict[str, Any]:
        return {"red_hue": self.red_hue, "blue_hue": self.blue_hue, "s_min": self.s_min, "v_min": self.v_min}

    def as_json(self) -> Dict[str, Any]:
        return {
            "red_hue": [list(r) for r in self.red_hue], "blue_hue": [list(r) for r in self.blue_hue],
            "s_min": self.s_min, "v_min": self.v_min,
        }


def _integer(v: Any, lo: int, hi: int) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not float(v).is_integer():
        raise ValueError(f"expected an integer, got {v!r}")
    if not lo <= v <= hi:
        raise ValueError(f"{v!r} is outside [{lo}, {hi}]")
    return int(v)


def _hue_ranges(v: Any) -> HueRanges:
    if not isinstance(v, list) or not v:
        raise ValueError(f"expected a list of [low, high] hue ranges, got {v!r}")
    if len(v) > MAX_RANGES:
        raise ValueError(f"at most {MAX_RANGES} ranges, got {len(v)}")
    out = []
    for r in v:
        if not isinstance(r, list) or len(r) != 2:
            raise ValueError(f"expected a [low, high] pair, got {r!r}")
        lo, hi = _integer(r[0], 0, 179), _integer(r[1], 0, 179)
        if lo > hi:
            raise ValueError(f"low {lo} is above high {hi} (a hue range that wraps is two: [0, 10], [165, 179])")
        out.append((lo, hi))
    return tuple(out)


def parse(data: Any, current: Thresholds) -> Thresholds:
    """Validate a request's JSON object into new thresholds; keys left out keep their ``current`` value.

    Raises
    ------
    RequestError
        Naming every bad key and why, e.g. ``s_min: 300 is outside [0, 255]``.
    """
    if not isinstance(data, Mapping):
        raise RequestError(f"expected a JSON object with some of {', '.join(KEYS)}, got {type(data).__name__}")
    problems = [f"{k}: unknown key (known: {', '.join(KEYS)})" for k in data if k not in KEYS]
    values: Dict[str, Any] = {}
    for key in KEYS:
        if key not in data:
            continue
        try:
            values[key] = _hue_ranges(data[key]) if key.endswith("_hue") else _integer(data[key], 0, 255)
        except ValueError as exc:
            problems.append(f"{key}: {exc}")
    if problems:
        raise RequestError("; ".join(problems))
    return dataclasses.replace(current, **values)
