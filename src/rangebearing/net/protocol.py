"""Wire format v1: one compact UTF-8 JSON object per UDP datagram, one per frame.

A datagram is sent for every processed frame, landmarks or not, so it doubles
as a heartbeat. Landmarks travel *column-wise*: ``"landmarks"`` is an object
whose keys are the unit-named fields and whose values are equal-length arrays,
one entry per landmark. Writing each landmark as its own object would repeat
~100 bytes of key names per landmark and push ten landmarks past one Ethernet
MTU; column-wise, ten fit in about 1 kB. ``docs/protocol.md`` is the consumer
documentation; ``schema/reading-v1.json`` is the JSON Schema.

Encoding and decoding are pure functions: no sockets, no clocks. The checks
of single values live in :mod:`rangebearing.net.values`.
"""

from __future__ import annotations

import json
import math
from typing import Any, Callable, Dict, Iterable, List, Optional, Protocol, Tuple

from .._compat import frozen
from ..errors import ProtocolError
from .values import (
    MAX_INTEGER,
    bearing,
    boolean,
    encoded,
    encoded_count,
    encoded_rate,
    encoded_sigma,
    encoded_track_id,
    fraction,
    id_number,
    integer,
    is_number,
    number,
    number_or_null,
    point,
    reject_constant,
    show,
    size,
    text,
)

PROTOCOL_VERSION = 1
MAX_DATAGRAM_BYTES = 65507  # the largest UDP payload over IPv4

# Rounding on the wire: 0.1 mm, 1e-5 rad (0.0006 degrees), 0.01 px, 1 µs.
M_DIGITS = 4
RAD_DIGITS = 5
PX_DIGITS = 2
T_DIGITS = 6
FPS_DIGITS = 2
MPS_DIGITS = 3  # rates: 1 mm/s, 1e-4 rad/s
RADPS_DIGITS = 4
VISIBLE_DIGITS = 2

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


def wire_time_ns(t: float) -> int:
    """``t`` (Unix s) as a reading carries it, to the µs, in integer ns: what MCAP log times use."""
    return round(round(float(t), T_DIGITS) * 1e6) * 1000


# --- encoding ---------------------------------------------------------------


def _xy(p: Any, what: str) -> List[float]:
    x, y = p
    return [encoded(x, PX_DIGITS, what), encoded(y, PX_DIGITS, what)]


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
        out["range_sigma_m"] = encoded_sigma(rs, M_DIGITS, "range_sigma_m")
        out["bearing_sigma_rad"] = encoded_sigma(bs, RAD_DIGITS, "bearing_sigma_rad")
    vis = getattr(lm, "visible", None)
    if vis is not None:
        out["visible"] = encoded(vis, VISIBLE_DIGITS, "visible", 0.0, 1.0)
    tid = getattr(lm, "track_id", None)
    if tid is not None:
        out["track_id"] = encoded_track_id(tid)
        out["range_rate_mps"] = encoded_rate(getattr(lm, "range_rate_mps", None), MPS_DIGITS, "range_rate_mps")
        br = getattr(lm, "bearing_rate_radps", None)
        out["bearing_rate_radps"] = encoded_rate(br, RADPS_DIGITS, "bearing_rate_radps")
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
        "range_m": encoded(lm.range_m, M_DIGITS, "range_m", lo=0.0),
        "bearing_rad": encoded(lm.bearing_rad, RAD_DIGITS, "bearing_rad", -math.pi, math.pi),
        "in_envelope": bool(lm.in_envelope),
        "l_px": encoded(lm.l_px, PX_DIGITS, "l_px", lo=0.0),
        "d_v_m": encoded(lm.d_v_m, M_DIGITS, "d_v_m"),
        "d_h_m": encoded(lm.d_h_m, M_DIGITS, "d_h_m"),
        "red_px": _xy(lm.red_xy_px, "red_px"),
        "blue_px": _xy(lm.blue_xy_px, "blue_px"),
        "width_px": encoded(lm.width_px, PX_DIGITS, "width_px", lo=0.0),
        **added_fields(lm),
    }


_COLUMNS = LANDMARK_FIELDS + ADDED_FIELDS
_SIGMA_FLOOR_M, _SIGMA_FLOOR_RAD = 10.0**-M_DIGITS, 10.0**-RAD_DIGITS
_ENCODER = json.JSONEncoder(separators=(",", ":"), allow_nan=False, check_circular=False)  # built once, not per call


def _row(lm: Any) -> Optional[Tuple[Any, ...]]:
    """Every column of one landmark, in :data:`_COLUMNS` order, as :func:`landmark_fields` would write them.

    The daemon's frame-rate path: one landmark carrying every column, plain
    finite numbers within the decoder's limits, checked in a few comparisons
    rather than a call per value. Anything else (a column missing, NaN, a
    bound crossed, a track id that is not an ``int``) gives None, and
    :func:`landmark_fields` encodes it or says what is wrong.
    """
    try:
        tid, rr, br = lm.track_id, lm.range_rate_mps, lm.bearing_rate_radps
        vals = tuple(map(float, (lm.range_m, lm.bearing_rad, lm.l_px, lm.d_v_m,
                                 lm.d_h_m, *lm.red_xy_px, *lm.blue_xy_px, lm.width_px, lm.range_sigma_m,
                                 lm.bearing_sigma_rad, lm.visible)))
        r, b, lpx, dv, dh, rx, ry, bx, by, w, rs, bs, vis = vals
        rr = None if rr is None else float(rr)  # no rate yet (a young track): null on the wire
        br = None if br is None else float(br)
    except (AttributeError, TypeError, ValueError, OverflowError):  # a column missing or not a number
        return None
    finite = math.isfinite(sum(vals) + (rr or 0.0) + (br or 0.0))  # NaN or inf anywhere makes the sum so
    if (type(tid) is not int or not -1 <= tid <= MAX_INTEGER or not finite
            or not (r >= 0.0 and -math.pi <= b <= math.pi and lpx >= 0.0 and w >= 0.0 and rs >= 0.0 and bs >= 0.0
                    and 0.0 <= vis <= 1.0)):
        return None
    rs, bs = round(rs, 12) + 0.0, round(bs, 12) + 0.0  # as encoded_sigma: never 0 on the wire when it is not
    return (
        round(r, M_DIGITS) + 0.0, round(b, RAD_DIGITS) + 0.0, bool(lm.in_envelope), round(lpx, PX_DIGITS) + 0.0,
        round(dv, M_DIGITS) + 0.0, round(dh, M_DIGITS) + 0.0,
        [round(rx, PX_DIGITS) + 0.0, round(ry, PX_DIGITS) + 0.0],
        [round(bx, PX_DIGITS) + 0.0, round(by, PX_DIGITS) + 0.0],
        round(w, PX_DIGITS) + 0.0,
        max(round(rs, M_DIGITS) + 0.0, _SIGMA_FLOOR_M) if rs > 0.0 else 0.0,
        max(round(bs, RAD_DIGITS) + 0.0, _SIGMA_FLOOR_RAD) if bs > 0.0 else 0.0,
        round(vis, VISIBLE_DIGITS) + 0.0, tid, None if rr is None else round(rr, MPS_DIGITS) + 0.0,
        None if br is None else round(br, RADPS_DIGITS) + 0.0,
    )


def _columns(landmarks: Iterable[LandmarkLike]) -> Dict[str, List[Any]]:
    lms = list(landmarks)
    fast = [_row(lm) for lm in lms]
    if not lms:
        return {name: [] for name in _COLUMNS}
    if None not in fast:
        return dict(zip(_COLUMNS, map(list, zip(*fast))))  # type: ignore[arg-type]
    rows = [landmark_fields(lm) for lm in lms]
    # an added column is written only when every landmark has it (always, for this daemon's own)
    names = LANDMARK_FIELDS + tuple(f for f in ADDED_FIELDS if all(f in r for r in rows))
    return {name: [r[name] for r in rows] for name in names}


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
    text(robot, "robot id")
    cols = _columns(landmarks)
    msg: Dict[str, Any] = {
        "v": PROTOCOL_VERSION,
        "robot": robot,
        "seq": encoded_count(seq, "seq"),
        "t": encoded(t, T_DIGITS, "t"),
        "landmarks": cols,
    }
    if fps is not None:
        msg["fps"] = encoded(fps, FPS_DIGITS, "fps")
    if dropped is not None:
        msg["dropped"] = encoded_count(dropped, "dropped")
    if omitted is not None:
        msg["omitted"] = encoded_count(omitted, "omitted")
    return _ENCODER.encode(msg).encode("ascii")


# --- decoding ---------------------------------------------------------------


_COLUMN_CHECKS: Dict[str, Callable[[Any, str], Any]] = {
    "range_m": size,
    "bearing_rad": bearing,
    "in_envelope": boolean,
    "l_px": size,
    "d_v_m": number,
    "d_h_m": number,
    "red_px": point,
    "blue_px": point,
    "width_px": size,
}


_ADDED_CHECKS: Dict[str, Callable[[Any, str], Any]] = {
    "range_sigma_m": size,
    "bearing_sigma_rad": size,
    "visible": fraction,
    "track_id": id_number,
    "range_rate_mps": number_or_null,
    "bearing_rate_radps": number_or_null,
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
        msg = json.loads(bytes(data).decode("utf-8"), parse_constant=reject_constant)
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
    if not is_number(v) or v != PROTOCOL_VERSION:
        raise ProtocolError(f"unsupported protocol version {show(v)} (this reader speaks v1)")
    missing = [name for name in READING_FIELDS if name not in msg]
    if missing:
        raise ProtocolError(f"missing field(s) {', '.join(missing)}")
    return Reading(
        robot=text(msg["robot"], "robot"),
        seq=integer(msg["seq"], "seq"),
        t=number(msg["t"], "t"),
        landmarks=_landmarks(msg["landmarks"]),
        fps=number(msg["fps"], "fps", 0.0) if "fps" in msg else None,
        dropped=integer(msg["dropped"], "dropped") if "dropped" in msg else None,
        sender=sender,
        omitted=integer(msg["omitted"], "omitted") if "omitted" in msg else None,
    )
