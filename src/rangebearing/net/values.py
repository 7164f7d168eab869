"""Checks of single wire values, both ways: what the encoder refuses to write and what the decoder refuses to read.

The two sides agree: the encoder never writes a value a decoder drops. Every
failure is a :class:`~rangebearing.errors.ProtocolError` whose message shows
at most ~40 characters of the offending value.
"""

from __future__ import annotations

import math
import operator
import sys
from typing import Any, Optional, Tuple

from ..errors import ProtocolError

# The decoder's limits are the schema's: a finite IEEE double, and integers a double holds exactly.
MAX_FINITE = sys.float_info.max
MAX_INTEGER = 2**53 - 1

XY = Tuple[float, float]

# --- encoding ---------------------------------------------------------------


def encoded(x: Any, digits: int, what: str, lo: float = -math.inf, hi: float = math.inf) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError, OverflowError):
        raise ProtocolError(f"cannot encode {what}={show(x)}: not a number") from None
    if not math.isfinite(v):
        raise ProtocolError(f"cannot encode {what}={v!r}: not a finite number")
    if not lo <= v <= hi:  # the limits decode_reading enforces: never send what a consumer must drop
        raise ProtocolError(f"cannot encode {what}={v!r}: outside [{lo:g}, {hi:g}]")
    return round(v, digits) + 0.0  # + 0.0 turns -0.0 into 0.0


def encoded_count(n: Any, what: str) -> int:
    try:
        i = operator.index(n)
    except TypeError:
        raise ProtocolError(f"{what} must be an integer >= 0, got {n!r}") from None
    if isinstance(n, bool) or not 0 <= i <= MAX_INTEGER:
        raise ProtocolError(f"{what} must be an integer in [0, 2**53 - 1], got {n!r}")
    return i


def encoded_sigma(x: Any, digits: int, what: str) -> float:
    """A one-sigma value, rounded up to the wire resolution: never 0 when it is not."""
    v = encoded(x, 12, what, lo=0.0)
    return max(encoded(v, digits, what), 10.0**-digits) if v > 0.0 else 0.0


def encoded_track_id(n: Any) -> int:
    if isinstance(n, bool):
        raise ProtocolError(f"track_id must be an integer >= -1, got {n!r}")
    try:
        i = operator.index(n)
    except TypeError:
        raise ProtocolError(f"track_id must be an integer >= -1, got {n!r}") from None
    if not -1 <= i <= MAX_INTEGER:
        raise ProtocolError(f"track_id must be an integer in [-1, 2**53 - 1], got {n!r}")
    return i


def encoded_rate(x: Any, digits: int, what: str) -> Optional[float]:
    return None if x is None else encoded(x, digits, what)


def reject_constant(name: str) -> Any:
    raise ProtocolError(f"{name} is not allowed in a reading")


def show(v: Any, limit: int = 40) -> str:
    """``repr(v)`` cut to ``limit`` characters: a hostile value never floods a message."""
    if isinstance(v, (dict, list)):
        return f"{type(v).__name__} of {len(v)}"
    text = repr(v) if not isinstance(v, int) or abs(v) < 10**limit else f"an integer of {len(str(abs(v)))} digits"
    return text if len(text) <= limit else text[: limit - 3] + "..."


def is_number(v: Any) -> bool:
    """A JSON number that fits a finite double (ints compared exactly: 10**309 is not)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return False
    return -MAX_FINITE <= v <= MAX_FINITE  # False for NaN, inf and out-of-range ints


def number(v: Any, where: str, lo: float = -math.inf, hi: float = math.inf) -> float:
    if not is_number(v) or not lo <= v <= hi:
        bound = "" if lo == -math.inf else f" >= {lo:g}"
        bound += "" if hi == math.inf else f" <= {hi:g}"
        raise ProtocolError(f"{where}: expected a finite number{bound}, got {show(v)}")
    return float(v)


def integer(v: Any, where: str) -> int:
    # JSON does not tell 5 from 5.0 (nor does the JSON Schema): both are the integer 5.
    if is_number(v) and float(v).is_integer() and 0 <= v <= MAX_INTEGER:
        return int(v)
    raise ProtocolError(f"{where}: expected an integer in [0, 2**53 - 1], got {show(v)}")


def boolean(v: Any, where: str) -> bool:
    if not isinstance(v, bool):
        raise ProtocolError(f"{where}: expected true or false, got {show(v)}")
    return v


def text(v: Any, where: str) -> str:
    if not isinstance(v, str) or not v:
        raise ProtocolError(f"{where}: expected a non-empty string, got {show(v)}")
    try:
        v.encode("utf-8")
    except UnicodeEncodeError:  # a lone surrogate ("\\ud800"): no consumer could print or store it
        raise ProtocolError(f"{where}: not valid Unicode text (lone surrogate)") from None
    return v


def point(v: Any, where: str) -> XY:
    if not isinstance(v, list) or len(v) != 2:
        raise ProtocolError(f"{where}: expected [x, y], got {show(v)}")
    return (number(v[0], where), number(v[1], where))


def bearing(v: Any, where: str) -> float:
    return number(v, where, -math.pi, math.pi)


def size(v: Any, where: str) -> float:
    return number(v, where, 0.0)


def fraction(v: Any, where: str) -> float:
    return number(v, where, 0.0, 1.0)


def id_number(v: Any, where: str) -> int:
    if is_number(v) and float(v).is_integer() and -1 <= v <= MAX_INTEGER:  # 7.0 is 7, as for seq
        return int(v)
    raise ProtocolError(f"{where}: expected an integer in [-1, 2**53 - 1], got {show(v)}")


def number_or_null(v: Any, where: str) -> Optional[float]:
    return None if v is None else number(v, where)


