"""Wire format v1: one compact UTF-8 JSON object per UDP datagram, one per frame.

A datagram is sent for every processed frame, landmarks or not, so it doubles
as a heartbeat. Landmarks travel *column-wise*: ``"landmarks"`` is an object
whose keys are the unit-named fields and whose values are equal-length arrays,
one entry per landmark. Writing each landmark as its own object would repeat
~100 bytes of key names per landmark and push ten landmarks past one Ethernet
MTU; column-wise, ten fit in about 1 kB. ``docs/protocol.md`` is the consumer
documentation; ``schema/reading-v1.json`` is the JSON Schema.

Encoding and decoding are pure functions: no sockets, no clocks.
"""

from __future__ import annotations

import json
import math
import operator
import sys
from typing import Any, Callable, Dict, Iterable, List, Optional, Protocol, Tuple

from .._compat import frozen
from ..errors import ProtocolError

PROTOCOL_VERSION = 1
MAX_DATAGRAM_BYTES = 65507  # the largest UDP payload over IPv4
# The decoder's limits are the schema's: a finite IEEE double, and integers a double holds exactly.
MAX_FINITE = sys.float_info.max
MAX_INTEGER = 2**53 - 1

# Rounding on the wire: 0.1 mm, 1e-5 rad (0.0006 degrees), 0.01 px, 1 µs.
M_DIGITS = 4
RAD_DIGITS = 5
PX_DIGITS = 2
T_DIGITS = 6
FPS_DIGITS = 2
MPS_DIGITS = 3  # rates: 1 mm/s, 1e-4 rad/s
RADPS_DIGITS = 4
VISIBLE_DIGITS = 2
MTU_PAYLOAD_BYTES = 1400  # what one Ethernet/Wi-Fi frame carries without IP fragmentation, with headroom

XY = Tuple[float, float]

# The landmark columns in wire order; every one is required in v1.
LANDMARK_FIELDS = (
    "range_m", "bearing_rad", "in_envelope", "l_px", "d_v_m", "d_h_m",
    "red_px", "blue_px", "width_px",
)
# Columns added within v1 (uncertainty, occlusion, track identity and rates): a decoder accepts a
# datagram without them; this encoder writes them whenever the landmarks carry them.
ADDED_FIELDS = (
    "range_sigma_m", "bearing_sigma_rad", "visible", "track_id", "range_rate_mps", "bearing_rate_radps",
)
READING_FIELDS = ("v", "robot", "seq", "t", "landmarks")  # required
OPTIONAL_FIELDS = ("fps", "dropped", "omitted")


class LandmarkLike(Protocol):
    """What the encoder reads from a landmark (:class:`~rangebearing.core.types.Landmark`
    and :class:`RemoteLandmark` both qualify)."""

    @property
    def range_m(self) -> float: ...
    @property
    def bearing_rad(self) -> float: ...
    @property
    def in_envelope(self) -> bool: ...
    @property
    def l_px(self) -> float: ...
    @property
    def d_v_m(self) -> float: ...
    @property
    def d_h_m(self) -> float: ...
    @property
    def red_xy_px(self) -> XY: ...
    @property
    def blue_xy_px(self) -> XY: ...
    @property
    def width_px(self) -> float: ...
    @property
    def range_sigma_m(self) -> Optional[float]: ...
    @property
    def bearing_sigma_rad(self) -> Optional[float]: ...
    @property
    def visible(self) -> Optional[float]: ...
    @property
    def track_id(self) -> Optional[int]: ...
    @property
    def range_rate_mps(self) -> Optional[float]: ...
    @property
    def bearing_rate_radps(self) -> Optional[float]: ...


@frozen
class RemoteLandmark:
    """One landmark as another robot reported it (same units as ``Landmark``).

    The added columns are ``None`` when the sender did not send them (an older
    sender); ``track_id`` is then ``None`` too, and ``-1`` when the sender
    processed its frames independently. The rates are also ``None`` while the
    sender's track is too young to have one.
    """

    range_m: float
    bearing_rad: float
    in_envelope: bool
    l_px: float
    d_v_m: float
    d_h_m: float
    red_xy_px: XY
    blue_xy_px: XY
    width_px: float
    range_sigma_m: Optional[float] = None
    bearing_sigma_rad: Optional[float] = None
    visible: Optional[float] = None
    track_id: Optional[int] = None
    range_rate_mps: Optional[float] = None
    bearing_rate_radps: Optional[float] = None


@frozen
class Reading:
    """One decoded datagram: what ``robot`` saw in frame ``seq`` captured at ``t``.

    ``t`` is the capture time in Unix seconds on the sender's clock. ``fps`` and
    ``dropped`` are ``None`` when the sender did not include them. ``sender`` is
    the ``(host, port)`` the datagram came from, when known. ``omitted`` counts
    landmarks seen but left out because the datagram would not have fitted one
    packet (the nearest were sent); ``None`` when nothing was left out.
    """

    robot: str
    seq: int
    t: float
    landmarks: Tuple[RemoteLandmark, ...] = ()
    fps: Optional[float] = None
    dropped: Optional[int] = None
    sender: Optional[Tuple[str, int]] = None
    omitted: Optional[int] = None

    def to_bytes(self) -> bytes:
        """Encode this reading again (``sender`` is not part of the datagram)."""
        return encode_reading(self.robot, self.seq, self.t, self.landmarks, self.fps, self.dropped,
                              omitted=self.omitted)


# --- encoding ---------------------------------------------------------------


def _num(x: Any, digits: int, what: str, lo: float = -math.inf, hi: float = math.inf) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError, OverflowError):
        raise ProtocolError(f"cannot encode {what}={_show(x)}: not a number") from None
    if not math.isfinite(v):
        raise ProtocolError(f"cannot encode {what}={v!r}: not a finite number")
    if not lo <= v <= hi:  # the limits decode_reading enforces: never send what a consumer must drop
        raise ProtocolError(f"cannot encode {what}={v!r}: outside [{lo:g}, {hi:g}]")
    return round(v, digits) + 0.0  # + 0.0 turns -0.0 into 0.0


def _count(n: Any, what: str) -> int:
    try:
        i = operator.index(n)
    except TypeError:
        raise ProtocolError(f"{what} must be an integer >= 0, got {n!r}") from None
    if isinstance(n, bool) or not 0 <= i <= MAX_INTEGER:
        raise ProtocolError(f"{what} must be an integer in [0, 2**53 - 1], got {n!r}")
    return i


def _xy(p: Any, what: str) -> List[float]:
    x, y = p
    return [_num(x, PX_DIGITS, what), _num(y, PX_DIGITS, what)]


def _sigma(x: Any, digits: int, what: str) -> float:
    """A one-sigma value, rounded up to the wire resolution: never 0 when it is not."""
    v = _num(x, 12, what, lo=0.0)
    return max(_num(v, digits, what), 10.0**-digits) if v > 0.0 else 0.0


def _track_id(n: Any) -> int:
    if isinstance(n, bool):
        raise ProtocolError(f"track_id must be an integer >= -1, got {n!r}")
    try:
        i = operator.index(n)
    except TypeError:
        raise ProtocolError(f"track_id must be an integer >= -1, got {n!r}") from None
    if not -1 <= i <= MAX_INTEGER:
        raise ProtocolError(f"track_id must be an integer in [-1, 2**53 - 1], got {n!r}")
    return i


def _rate(x: Any, digits: int, what: str) -> Optional[float]:
    return None if x is None else _num(x, digits, what)


def added_fields(lm: LandmarkLike) -> Dict[str, Any]:
    """The added columns this landmark carries (see :data:`ADDED_FIELDS`), rounded and checked.

    A group is left out when the landmark lacks it (a :class:`RemoteLandmark`
    from an older sender): the sigmas together, ``visible``, and ``track_id``
    with the two rates. A rate of ``None`` (no track history yet) is kept:
    it goes on the wire as ``null``.
    """
    out: Dict[str, Any] = {}
    rs, bs = getattr(lm, "range_sigma_m", None), getattr(lm, "bearing_sigma_rad", None)
    if rs is not None and bs is not None:
        out["range_sigma_m"] = _sigma(rs, M_DIGITS, "range_sigma_m")
        out["bearing_sigma_rad"] = _sigma(bs, RAD_DIGITS, "bearing_sigma_rad")
    vis = getattr(lm, "visible", None)
    if vis is not None:
        out["visible"] = _num(vis, VISIBLE_DIGITS, "visible", 0.0, 1.0)
    tid = getattr(lm, "track_id", None)
    if tid is not None:
        out["track_id"] = _track_id(tid)
        out["range_rate_mps"] = _rate(getattr(lm, "range_rate_mps", None), MPS_DIGITS, "range_rate_mps")
        out["bearing_rate_radps"] = _rate(getattr(lm, "bearing_rate_radps", None), RADPS_DIGITS, "bearing_rate_radps")
    return out


def landmark_fields(lm: LandmarkLike) -> Dict[str, Any]:
    """One landmark's wire fields, rounded and checked: what a datagram carries, and what
    ``replay --out`` writes per landmark (the added columns included, see :func:`added_fields`).

    Raises
    ------
    ProtocolError
        A value is not finite or is outside what :func:`decode_reading` accepts.
    """
    return {
        "range_m": _num(lm.range_m, M_DIGITS, "range_m", lo=0.0),
        "bearing_rad": _num(lm.bearing_rad, RAD_DIGITS, "bearing_rad", -math.pi, math.pi),
        "in_envelope": bool(lm.in_envelope),
        "l_px": _num(lm.l_px, PX_DIGITS, "l_px", lo=0.0),
        "d_v_m": _num(lm.d_v_m, M_DIGITS, "d_v_m"),
        "d_h_m": _num(lm.d_h_m, M_DIGITS, "d_h_m"),
        "red_px": _xy(lm.red_xy_px, "red_px"),
        "blue_px": _xy(lm.blue_xy_px, "blue_px"),
        "width_px": _num(lm.width_px, PX_DIGITS, "width_px", lo=0.0),
        **added_fields(lm),
    }


def encode_reading(
    robot: str,
    seq: int,
    t: float,
    landmarks: Iterable[LandmarkLike] = (),
    fps: Optional[float] = None,
    dropped: Optional[int] = None,
    omitted: Optional[int] = None,
) -> bytes:
    """Encode one frame's landmarks as a v1 datagram.

    Parameters
    ----------
    robot : str
        Sender id (``publish.robot_id``), non-empty.
    seq : int
        The sender's count of processed frames, >= 0.
    t : float
        Capture time, Unix seconds.
    landmarks : iterable of Landmark or RemoteLandmark
        Everything seen in the frame; empty is a heartbeat.
    fps, dropped : float, int, optional
        Frame statistics; left out of the datagram when ``None``.
    omitted : int, optional
        Landmarks seen but not in ``landmarks`` (see :func:`~rangebearing.net.fit.encode_fitting`).

    Returns
    -------
    bytes
        Compact ASCII JSON. Metres are rounded to 0.1 mm, radians to 1e-5,
        pixels to 0.01 px, ``t`` to 1 µs, ``fps`` to 0.01.

    Raises
    ------
    ProtocolError
        An argument cannot be represented (empty robot id, negative seq,
        a NaN or infinite number).
    """
    _text(robot, "robot id")
    rows = [landmark_fields(lm) for lm in landmarks]
    # an added column is written only when every landmark has it (always, for this daemon's own)
    names = LANDMARK_FIELDS + tuple(f for f in ADDED_FIELDS if all(f in r for r in rows))
    cols: Dict[str, List[Any]] = {name: [r[name] for r in rows] for name in names}
    msg: Dict[str, Any] = {
        "v": PROTOCOL_VERSION,
        "robot": robot,
        "seq": _count(seq, "seq"),
        "t": _num(t, T_DIGITS, "t"),
        "landmarks": cols,
    }
    if fps is not None:
        msg["fps"] = _num(fps, FPS_DIGITS, "fps")
    if dropped is not None:
        msg["dropped"] = _count(dropped, "dropped")
    if omitted is not None:
        msg["omitted"] = _count(omitted, "omitted")
    return json.dumps(msg, separators=(",", ":"), allow_nan=False).encode("ascii")


# --- decoding ---------------------------------------------------------------


def _reject_constant(name: str) -> Any:
    raise ProtocolError(f"{name} is not allowed in a reading")


def _show(v: Any, limit: int = 40) -> str:
    """``repr(v)`` cut to ``limit`` characters: a hostile value never floods a message."""
    if isinstance(v, (dict, list)):
        return f"{type(v).__name__} of {len(v)}"
    text = repr(v) if not isinstance(v, int) or abs(v) < 10**limit else f"an integer of {len(str(abs(v)))} digits"
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _is_number(v: Any) -> bool:
    """A JSON number that fits a finite double (ints compared exactly: 10**309 is not)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return False
    return -MAX_FINITE <= v <= MAX_FINITE  # False for NaN, inf and out-of-range ints


def _number(v: Any, where: str, lo: float = -math.inf, hi: float = math.inf) -> float:
    if not _is_number(v) or not lo <= v <= hi:
        bound = "" if lo == -math.inf else f" >= {lo:g}"
        bound += "" if hi == math.inf else f" <= {hi:g}"
        raise ProtocolError(f"{where}: expected a finite number{bound}, got {_show(v)}")
    return float(v)


def _integer(v: Any, where: str) -> int:
    # JSON does not tell 5 from 5.0 (nor does the JSON Schema): both are the integer 5.
    if _is_number(v) and float(v).is_integer() and 0 <= v <= MAX_INTEGER:
        return int(v)
    raise ProtocolError(f"{where}: expected an integer in [0, 2**53 - 1], got {_show(v)}")


def _boolean(v: Any, where: str) -> bool:
    if not isinstance(v, bool):
        raise ProtocolError(f"{where}: expected true or false, got {_show(v)}")
    return v


def _text(v: Any, where: str) -> str:
    if not isinstance(v, str) or not v:
        raise ProtocolError(f"{where}: expected a non-empty string, got {_show(v)}")
    try:
        v.encode("utf-8")
    except UnicodeEncodeError:  # a lone surrogate ("\\ud800"): no consumer could print or store it
        raise ProtocolError(f"{where}: not valid Unicode text (lone surrogate)") from None
    return v


def _point(v: Any, where: str) -> XY:
    if not isinstance(v, list) or len(v) != 2:
        raise ProtocolError(f"{where}: expected [x, y], got {_show(v)}")
    return (_number(v[0], where), _number(v[1], where))


def _bearing(v: Any, where: str) -> float:
    return _number(v, where, -math.pi, math.pi)


def _size(v: Any, where: str) -> float:
    return _number(v, where, 0.0)


_COLUMN_CHECKS: Dict[str, Callable[[Any, str], Any]] = {
    "range_m": _size,
    "bearing_rad": _bearing,
    "in_envelope": _boolean,
    "l_px": _size,
    "d_v_m": _number,
    "d_h_m": _number,
    "red_px": _point,
    "blue_px": _point,
    "width_px": _size,
}


def _fraction(v: Any, where: str) -> float:
    return _number(v, where, 0.0, 1.0)


def _id(v: Any, where: str) -> int:
    if _is_number(v) and float(v).is_integer() and -1 <= v <= MAX_INTEGER:  # 7.0 is 7, as for seq
        return int(v)
    raise ProtocolError(f"{where}: expected an integer in [-1, 2**53 - 1], got {_show(v)}")


def _number_or_null(v: Any, where: str) -> Optional[float]:
    return None if v is None else _number(v, where)


_ADDED_CHECKS: Dict[str, Callable[[Any, str], Any]] = {
    "range_sigma_m": _size,
    "bearing_sigma_rad": _size,
    "visible": _fraction,
    "track_id": _id,
    "range_rate_mps": _number_or_null,
    "bearing_rate_radps": _number_or_null,
}


def _landmarks(cols: Any) -> Tuple[RemoteLandmark, ...]:
    if not isinstance(cols, dict):
        raise ProtocolError(f"landmarks: expected an object of columns, got {type(cols).__name__}")
    missing = [name for name in LANDMARK_FIELDS if name not in cols]
    if missing:
        raise ProtocolError(f"landmarks: missing column(s) {', '.join(missing)}")
    n: Optional[int] = None
    values: Dict[str, List[Any]] = {}
    for name in LANDMARK_FIELDS + tuple(f for f in ADDED_FIELDS if f in cols):
        col = cols[name]
        if not isinstance(col, list):
            raise ProtocolError(f"landmarks.{name}: expected an array, got {type(col).__name__}")
        if n is not None and len(col) != n:
            raise ProtocolError(f"landmarks.{name}: {len(col)} entries, other columns have {n}")
        n = len(col)
        check = _COLUMN_CHECKS.get(name) or _ADDED_CHECKS[name]
        values[name] = [check(v, f"landmarks.{name}[{i}]") for i, v in enumerate(col)]
    absent = [None] * (n or 0)
    added = {name: values.get(name, absent) for name in ADDED_FIELDS}
    return tuple(
        RemoteLandmark(
            range_m=values["range_m"][i],
            bearing_rad=values["bearing_rad"][i],
            in_envelope=values["in_envelope"][i],
            l_px=values["l_px"][i],
            d_v_m=values["d_v_m"][i],
            d_h_m=values["d_h_m"][i],
            red_xy_px=values["red_px"][i],
            blue_xy_px=values["blue_px"][i],
            width_px=values["width_px"][i],
            **{name: added[name][i] for name in ADDED_FIELDS},
        )
        for i in range(n or 0)
    )


def decode_reading(data: bytes, sender: Optional[Tuple[str, int]] = None) -> Reading:
    """Decode and check one datagram.

    Types and required fields are checked strictly; unknown extra fields (at
    the top level or as extra landmark columns) are ignored, so v1 readers
    keep working when v1 writers add fields.

    Raises
    ------
    ProtocolError
        The datagram is not UTF-8 JSON, not an object, not a rangebearing
        reading, of another version, or has a missing or ill-typed field.
    """
    if not isinstance(data, (bytes, bytearray, memoryview)):
        raise ProtocolError(f"expected bytes, got {type(data).__name__}")
    if len(data) > MAX_DATAGRAM_BYTES:
        raise ProtocolError(f"datagram of {len(data)} bytes is larger than any UDP payload")
    try:
        msg = json.loads(bytes(data).decode("utf-8"), parse_constant=_reject_constant)
    except UnicodeDecodeError:
        raise ProtocolError("datagram is not UTF-8 text") from None
    except ProtocolError:
        raise
    except (ValueError, RecursionError) as exc:  # JSONDecodeError is a ValueError; so is a 5,000-digit integer
        raise ProtocolError(f"datagram is not JSON: {str(exc)[:80]}") from None
    try:
        return _reading(msg, sender)
    except ProtocolError:
        raise
    except (TypeError, ValueError, OverflowError, RecursionError) as exc:  # a check above missed a case
        raise ProtocolError(f"malformed reading: {type(exc).__name__}: {str(exc)[:80]}") from None


def _reading(msg: Any, sender: Optional[Tuple[str, int]]) -> Reading:
    if not isinstance(msg, dict) or "v" not in msg:
        raise ProtocolError("not a rangebearing reading (no \"v\" field)")
    v = msg["v"]
    if not _is_number(v) or v != PROTOCOL_VERSION:
        raise ProtocolError(f"unsupported protocol version {_show(v)} (this reader speaks v1)")
    missing = [name for name in READING_FIELDS if name not in msg]
    if missing:
        raise ProtocolError(f"missing field(s) {', '.join(missing)}")
    return Reading(
        robot=_text(msg["robot"], "robot"),
        seq=_integer(msg["seq"], "seq"),
        t=_number(msg["t"], "t"),
        landmarks=_landmarks(msg["landmarks"]),
        fps=_number(msg["fps"], "fps", 0.0) if "fps" in msg else None,
        dropped=_integer(msg["dropped"], "dropped") if "dropped" in msg else None,
        sender=sender,
        omitted=_integer(msg["omitted"], "omitted") if "omitted" in msg else None,
    )
