"""Datagrams that always fit one packet: the nearest landmarks that fit, and a count of the rest.

A datagram larger than :data:`MTU_PAYLOAD_BYTES` would be fragmented by IP (one
lost fragment loses the reading) and one over 65,507 bytes cannot be sent at
all. ``--check`` refuses a ``max_landmarks`` whose full datagram could be too
large; this is the safety net for the frame that still is (an unusually long
number, a bigger camera): it is sent with fewer landmarks, never not at all.
"""

from __future__ import annotations

from typing import Iterable, Optional, Sequence

from .protocol import LandmarkLike, encode_reading

MTU_PAYLOAD_BYTES = 1400  # one Ethernet/Wi-Fi frame without IP fragmentation, with headroom for headers


def encode_fitting(
    robot: str,
    seq: int,
    t: float,
    landmarks: Iterable[LandmarkLike] = (),
    fps: Optional[float] = None,
    dropped: Optional[int] = None,
    max_bytes: int = MTU_PAYLOAD_BYTES,
) -> bytes:
    """:func:`~rangebearing.net.protocol.encode_reading`, cut to ``max_bytes``.

    When every landmark fits, the datagram is exactly ``encode_reading``'s.
    Otherwise it carries the nearest landmarks that fit (by ``range_m``) and
    ``"omitted": n``, the number left out; with none that fit it is a heartbeat
    with every landmark counted in ``omitted``.

    Raises
    ------
    ProtocolError
        As ``encode_reading`` (a value that cannot be represented).
    """
    lms: Sequence[LandmarkLike] = list(landmarks)
    full = encode_reading(robot, seq, t, lms, fps, dropped)
    if len(full) <= max_bytes:
        return full
    nearest = sorted(lms, key=lambda lm: lm.range_m)
    lo, hi = 0, len(nearest) - 1  # the largest count that fits lies in [lo, hi]
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if len(encode_reading(robot, seq, t, nearest[:mid], fps, dropped, omitted=len(lms) - mid)) <= max_bytes:
            lo = mid
        else:
            hi = mid - 1
    return encode_reading(robot, seq, t, nearest[:lo], fps, dropped, omitted=len(lms) - lo)
