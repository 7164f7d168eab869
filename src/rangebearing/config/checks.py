"""Per-key checks for the config loader.

A check takes the raw YAML value and returns the normalised value, or raises
ValueError with a short reason that the loader prefixes with the key.
"""

from __future__ import annotations

import ipaddress
import math
from typing import Any, Callable, Mapping, Tuple

Check = Callable[[Any], Any]


def number(lo: float = -math.inf, hi: float = math.inf, integer: bool = False) -> Check:
    def check(v: Any) -> Any:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise ValueError(f"expected a number, got {v!r}")
        if integer and not float(v).is_integer():
            raise ValueError(f"expected an integer, got {v!r}")
        if not math.isfinite(v) or not lo <= v <= hi:
            raise ValueError(f"{v!r} is outside [{lo}, {hi}]")
        return int(v) if integer else float(v)

    return check


def positive(integer: bool = False) -> Check:
    inner = number(0, math.inf, integer)

    def check(v: Any) -> Any:
        out = inner(v)
        if out <= 0:
            raise ValueError(f"must be > 0, got {v!r}")
        return out

    return check


def boolean(v: Any) -> bool:
    if not isinstance(v, bool):
        raise ValueError(f"expected true or false, got {v!r}")
    return v


def choice(*choices: str) -> Check:
    def check(v: Any) -> str:
        if v not in choices:
            raise ValueError(f"{v!r} is not one of {', '.join(choices)}")
        return str(v)

    return check


def string(v: Any) -> str:
    if isinstance(v, bool) or not isinstance(v, (str, int)):
        raise ValueError(f"expected a string, got {v!r}")
    return str(v)


def odd_ksize(v: Any) -> int:
    n = number(1, 99, integer=True)(v)
    if n % 2 == 0:
        raise ValueError(f"must be odd, got {n}")
    return int(n)


def pair(lo: float, hi: float, integer: bool = False, ordered: bool = True) -> Check:
    num = number(lo, hi, integer)

    def check(v: Any) -> Tuple[Any, Any]:
        if not isinstance(v, (list, tuple)) or len(v) != 2:
            raise ValueError(f"expected a pair [low, high], got {v!r}")
        a, b = num(v[0]), num(v[1])
        if ordered and a > b:
            raise ValueError(f"low {a} is above high {b}")
        return (a, b)

    return check


def hue_ranges(v: Any) -> Tuple[Tuple[int, int], ...]:
    if isinstance(v, (list, tuple)) and len(v) == 2 and all(isinstance(x, int) for x in v):
        v = [v]
    if not isinstance(v, (list, tuple)) or not v:
        raise ValueError(f"expected a list of [low, high] hue ranges (0-179), got {v!r}")
    return tuple(pair(0, 179, integer=True)(r) for r in v)


def distortion(v: Any) -> Tuple[float, ...]:
    if not isinstance(v, (list, tuple)) or len(v) not in (4, 5, 8):
        raise ValueError(f"expected 4, 5 or 8 OpenCV coefficients, got {v!r}")
    return tuple(number()(c) for c in v)


def host_port(v: Any) -> Tuple[str, int]:
    if isinstance(v, str) and v.rpartition(":")[0]:
        host, _, port = v.rpartition(":")
        return (host.strip("[]"), number(1, 65535, integer=True)(int(port) if port.isdigit() else port))
    raise ValueError(f"expected 'host:port', got {v!r}")


def destinations(v: Any) -> Tuple[Tuple[str, int], ...]:
    if not isinstance(v, (list, tuple)):
        raise ValueError(f"expected a list of 'host:port', got {v!r}")
    return tuple(host_port(d) for d in v)


def controls(v: Any) -> Tuple[Tuple[str, Any], ...]:
    if v is None:
        return ()
    if not isinstance(v, Mapping):
        raise ValueError(f"expected a mapping of Picamera2 control names to values, got {v!r}")
    out = []
    for key, val in v.items():
        if not isinstance(key, str) or not key[:1].isupper():
            raise ValueError(f"control name {key!r} should be a libcamera control such as AeEnable")
        if isinstance(val, list):
            val = tuple(val)
        out.append((key, val))
    return tuple(out)


def is_ipv4_multicast(text: str) -> bool:
    """True for a dotted-quad IPv4 multicast address (224.0.0.0/4), such as ``239.255.47.80``."""
    try:
        return ipaddress.IPv4Address(text).is_multicast
    except (ipaddress.AddressValueError, ValueError):
        return False
