"""Per-key checks for the config loader.

A check takes the raw YAML value and returns the normalised value, or raises
ValueError with a short reason that the loader prefixes with the key; a check
of a list raises :class:`Invalid` naming every bad entry (``[2]: ...``). Values
are shown cut (:func:`show`): a message never carries a whole hostile value.
"""

from __future__ import annotations

import ipaddress
import math
import re
from typing import Any, Callable, Dict, List, Mapping, Tuple, Union

Check = Callable[[Any], Any]

MAX_DESTINATIONS = 32  # unicast destinations: one socket each
ROBOT_ID = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,63}")
_LABEL = r"[A-Za-z0-9_]([A-Za-z0-9_-]{0,61}[A-Za-z0-9_])?"
HOSTNAME = re.compile(rf"(?=.{{1,253}}$){_LABEL}(\.{_LABEL})*\.?")
PORT = re.compile(r"[0-9]{1,5}")


class Invalid(ValueError):
    """Problems in entries of one value: ``(where, message)`` pairs, ``where`` like ``"[2]"``."""

    def __init__(self, problems: List[Tuple[str, str]]) -> None:
        self.problems = problems
        super().__init__("; ".join(f"{w}: {m}" for w, m in problems))


def show(v: Any, limit: int = 40) -> str:
    """A value as a message shows it: YAML spelling for booleans and null, cut to ``limit``."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if v is None:
        return "null (nothing)"
    if isinstance(v, (list, tuple)):
        return f"a list of {len(v)}" if len(v) > 4 else _cut(repr(list(v)), limit)
    if isinstance(v, Mapping):
        return f"a mapping of {len(v)} key{'s' if len(v) != 1 else ''}"
    if isinstance(v, int) and abs(v) >= 10**limit:
        return f"an integer of {len(str(abs(v)))} digits"
    return _cut(repr(v), limit)


def _cut(text: str, limit: int) -> str:
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _fmt(x: float) -> str:
    return f"{x:g}"


def number(lo: float = -math.inf, hi: float = math.inf, integer: bool = False, above: float = -math.inf) -> Check:
    """A number in ``[lo, hi]`` (and ``> above``); the message says exactly what is allowed."""
    kind = "an integer" if integer else "a number"
    if above > -math.inf:
        allowed = f"{kind} > {_fmt(above)}" + (f" and <= {_fmt(hi)}" if hi < math.inf else "")
    elif lo > -math.inf and hi < math.inf:
        allowed = f"{kind} from {_fmt(lo)} to {_fmt(hi)}"
    elif lo > -math.inf:
        allowed = f"{kind} >= {_fmt(lo)}"
    else:
        allowed = kind if hi == math.inf else f"{kind} <= {_fmt(hi)}"

    def check(v: Any) -> Any:
        ok = not isinstance(v, bool) and isinstance(v, (int, float))
        # ints are compared exactly: 10**400 is not a float and never becomes one
        ok = ok and -1.8e308 < v < 1.8e308 and not (isinstance(v, float) and math.isnan(v))
        ok = ok and (not integer or float(v).is_integer()) and lo <= v <= hi and v > above
        if not ok:
            raise ValueError(f"must be {allowed}, got {show(v)}{_text_number_hint(v)}")
        return int(v) if integer else float(v)

    return check


def _text_number_hint(v: Any) -> str:
    """Why a number the user wrote is text: YAML 1.1 reads ``35e-3`` (no dot) or ``'634'`` as a string."""
    try:
        ok = isinstance(v, str) and len(v) <= 40 and math.isfinite(float(v.strip()))
    except ValueError:
        ok = False
    return " (YAML reads it as text: write it unquoted, with a dot before any exponent, e.g. 35.0e-3)" if ok else ""


def positive(integer: bool = False) -> Check:
    return number(integer=integer, above=0)


def boolean(v: Any) -> bool:
    if not isinstance(v, bool):
        raise ValueError(f"expected true or false, got {show(v)}")
    return v


def boolean_or(word: str) -> Check:
    """true, false or ``word`` (e.g. ``auto``)."""
    def check(v: Any) -> Union[bool, str]:
        if not isinstance(v, bool) and v != word:
            raise ValueError(f"expected true, false or {word}, got {show(v)}")
        return v

    return check


def choice(*choices: str) -> Check:
    def check(v: Any) -> str:
        if isinstance(v, bool):  # off/on/yes/no unquoted are YAML booleans
            raise ValueError(f"got the YAML boolean {show(v)} (unquoted on/off/yes/no are booleans); "
                             f"expected one of: {', '.join(choices)}")
        if not isinstance(v, str) or v not in choices:
            raise ValueError(f"expected one of: {', '.join(choices)}; got {show(v)}")
        return v

    return check


def string(v: Any) -> str:
    """Text without control characters (an integer is taken as its digits, e.g. ``device: 0``)."""
    if isinstance(v, bool) or not isinstance(v, (str, int)):
        raise ValueError(f"expected a string, got {show(v)}")
    text = str(v)
    bad = next((c for c in text if not c.isprintable() or "\ud800" <= c <= "\udfff"), None)
    if bad is not None:
        raise ValueError(f"contains the control character {bad!r} (in {show(text)})")
    if len(text) > 4096:
        raise ValueError(f"is {len(text)} characters long; at most 4096")
    return text


def robot_id(v: Any) -> str:
    if not isinstance(v, str) or not ROBOT_ID.fullmatch(v):
        raise ValueError("must be 1-64 letters, digits, '.', '_' or '-', starting with a letter or digit "
                         f"(it names the robot in every datagram); got {show(v)}")
    return v


def odd_ksize(v: Any) -> int:
    n = number(1, 99, integer=True)(v)
    if n % 2 == 0:
        raise ValueError(f"must be odd, got {n}")
    return int(n)


def pair(lo: float, hi: float, integer: bool = False, ordered: bool = True) -> Check:
    num = number(lo, hi, integer)

    def check(v: Any) -> Tuple[Any, Any]:
        if not isinstance(v, (list, tuple)) or len(v) != 2:
            raise ValueError(f"expected a pair [low, high], got {show(v)}")
        a, b = num(v[0]), num(v[1])
        if ordered and a > b:
            raise ValueError(f"low {a} is above high {b}")
        return (a, b)

    return check


def _entries(v: Any, check: Check, what: str, max_len: int = 64) -> Tuple[Any, ...]:
    """Check every entry of a list; report every bad one, not the first."""
    if not isinstance(v, (list, tuple)):
        raise ValueError(f"expected a list of {what}, got {show(v)}")
    if len(v) > max_len:
        raise ValueError(f"{len(v)} entries; at most {max_len}")
    out, problems = [], []
    for i, entry in enumerate(v):
        try:
            out.append(check(entry))
        except ValueError as exc:
            problems.append((f"[{i}]", str(exc)))
    if problems:
        raise Invalid(problems)
    return tuple(out)


def hue_ranges(v: Any) -> Tuple[Tuple[int, int], ...]:
    what = "[low, high] hue ranges (0-179), e.g. [[0, 10], [165, 179]]"
    if isinstance(v, (list, tuple)) and v and not any(isinstance(x, (list, tuple)) for x in v):
        raise ValueError(f"expected a list of {what}; a flat {show(v)} is not (write [{show(list(v))}])")
    if isinstance(v, (list, tuple)) and not v:
        raise ValueError(f"expected at least one of {what}")
    return _entries(v, pair(0, 179, integer=True), what, max_len=8)


def distortion(v: Any) -> Tuple[float, ...]:
    if not isinstance(v, (list, tuple)) or len(v) not in (4, 5, 8):
        raise ValueError(f"expected 4, 5 or 8 OpenCV coefficients, got {show(v)}")
    return _entries(v, number(-1e6, 1e6), "coefficients")


def _host(text: str) -> str:
    host = text[1:-1] if text.startswith("[") and text.endswith("]") else text
    try:
        return str(ipaddress.ip_address(host))
    except ValueError:
        pass
    if not host.isascii() or not HOSTNAME.fullmatch(host) or host.replace(".", "").isdigit():
        raise ValueError(f"{show(host)} is not an IP address or a host name")
    return host


def host_port(v: Any) -> Tuple[str, int]:
    if not isinstance(v, str) or not v.rpartition(":")[0]:
        raise ValueError(f"expected 'host:port', got {show(v)}")
    host, _, port = v.rpartition(":")
    if not PORT.fullmatch(port) or not 1 <= int(port) <= 65535:
        raise ValueError(f"port {show(port)} is not a number from 1 to 65535 (in {show(v)})")
    return (_host(host), int(port))


def destinations(v: Any) -> Tuple[Tuple[str, int], ...]:
    dests = _entries(v, host_port, "'host:port' strings", max_len=MAX_DESTINATIONS)
    first: Dict[Tuple[str, int], int] = {}
    problems = []
    for i, (host, port) in enumerate(dests):
        key = (host.lower().rstrip("."), port)
        if key in first:
            problems.append((f"[{i}]", f"same destination as [{first[key]}] ({host}:{port})"))
        first.setdefault(key, i)
    if problems:
        raise Invalid(problems)
    return dests


def multicast_group(v: Any) -> str:
    text = string(v)
    if text and not is_ipv4_multicast(text):
        raise ValueError(f"{show(text)} is not an IPv4 multicast address (224.0.0.0 to 239.255.255.255)")
    return text


def controls(v: Any) -> Tuple[Tuple[str, Any], ...]:
    if v is None:
        return ()
    if not isinstance(v, Mapping):
        raise ValueError(f"expected a mapping of Picamera2 control names to values, got {show(v)}")
    out, problems = [], []
    for key, val in v.items():
        if not isinstance(key, str) or not key[:1].isupper() or not key.isalnum():
            problems.append((f"[{show(key)}]", "should be a libcamera control name such as AeEnable"))
            continue
        items = val if isinstance(val, list) else [val]
        if len(items) > 16 or not all(isinstance(x, (bool, int, float)) for x in items):
            problems.append((f".{key}", f"expected a number, true/false or a short list of numbers, got {show(val)}"))
            continue
        out.append((key, tuple(val) if isinstance(val, list) else val))
    if problems:
        raise Invalid(problems)
    return tuple(out)


def is_ipv4_multicast(text: str) -> bool:
    """True for a dotted-quad IPv4 multicast address (224.0.0.0/4), such as ``239.255.47.80``."""
    try:
        return ipaddress.IPv4Address(text).is_multicast
    except (ipaddress.AddressValueError, ValueError):
        return False


class Section:
    """A nested section (``publish.zenoh``): the loader checks its keys one by one and names each."""

    def __init__(self, cls: type, checks: Mapping[str, Check]) -> None:
        self.cls = cls
        self.checks = dict(checks)


# <protocol>/<address>[?<metadata>][#<config>], as Zenoh spells endpoints.
ENDPOINT = re.compile(r"^[a-z][a-z0-9+-]*/[^\s?#/][^\s?#]*(\?[^\s#]*)?(#\S*)?$")
_KEY_BAD = re.compile(r"[*$?#\s]|//|^/|/$")
_CHUNK_BAD = re.compile(r"[/*$?#\s]")


def is_key_chunk(text: str) -> bool:
    """True when ``text`` can stand for ``{robot}`` in a Zenoh key (one chunk, no wildcard)."""
    return bool(text) and not _CHUNK_BAD.search(text)


def endpoints(v: Any) -> Tuple[str, ...]:
    if v is None:
        return ()
    if not isinstance(v, (list, tuple)):
        raise ValueError(f"expected a list of endpoints like 'tcp/192.168.1.10:7447', got {v!r}")
    bad = [e for e in v if not isinstance(e, str) or not ENDPOINT.match(e)]
    if bad:
        raise ValueError(f"{', '.join(repr(e) for e in bad)}: not <protocol>/<address> like 'tcp/192.168.1.10:7447'")
    return tuple(v)


def key_template(v: Any) -> str:
    """A Zenoh key to put on, where ``{robot}`` stands for the robot id: no wildcards."""
    text = string(v)
    if "{robot}" not in text:
        raise ValueError(f"{text!r} must contain {{robot}} so that robots do not share a key")
    if _KEY_BAD.search(text.replace("{robot}", "x")):
        raise ValueError(f"{text!r} is not a plain Zenoh key (no *, $, ?, #, spaces, empty or outer '/')")
    return text
