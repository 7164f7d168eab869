"""Datagrams that always fit one packet: the nearest landmarks that fit, and a count of the rest.

A datagram larger than :data:`MTU_PAYLOAD_BYTES` would be fragmented by IP (one
lost fragment loses the reading) and one over 65,507 bytes cannot be sent at
all. Detection is bounded by ``detection.max_landmarks`` (16), not by the
packet: up to 8 landmarks always fit (:func:`landmarks_that_fit`), typically
10; a frame with more is sent with the nearest that fit, never not at all.
"""

from __future__ import annotations

from typing import Iterable, Optional, Sequence

from ..core.types import Landmark
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


def _worst_landmark(width_px: int, height_px: int) -> Landmark:
    """A landmark whose every field takes as many characters on the wire as a real one can."""
    edge = float(max(width_px, height_px)) - 0.01  # a centroid at the far edge: most digits
    return Landmark(
        range_m=99.9999, bearing_rad=-3.14159, d_v_m=-99.9999, d_h_m=-99.9999, l_px=edge,
        red_xy_px=(edge, edge), blue_xy_px=(edge, edge), width_px=edge, bbox_px=(0, 0, 1, 1),
        in_envelope=False, range_sigma_m=99.9999, bearing_sigma_rad=3.14159, visible=0.99,
        track_id=99_999_999, range_rate_mps=-99.999, bearing_rate_radps=-9.9999,
    )


def worst_case_bytes(robot: str, n_landmarks: int, width_px: int = 640, height_px: int = 480) -> int:
    """The largest datagram ``n_landmarks`` landmarks can make (every column, every digit, every field).

    Built with the real encoder, so a column added to the wire format is counted too. Bounds
    assumed: ``seq`` and ``dropped`` under 10**11 (a century at 30 fps), ranges and offsets
    under 100 m, track ids under 10**8, centroids inside the image; a frame beyond them is
    still sent, by :func:`encode_fitting`, with its farthest landmarks counted in ``omitted``.
    """
    lm = _worst_landmark(width_px, height_px)
    return len(encode_reading(robot, 10**11 - 1, 4102444800.123456, [lm] * n_landmarks, 9999.99, 10**11 - 1))


def landmarks_that_fit(robot: str, width_px: int = 640, height_px: int = 480,
                       max_bytes: int = MTU_PAYLOAD_BYTES) -> int:
    """How many landmarks always fit in ``max_bytes`` (0 when not even a heartbeat does)."""
    n = 0
    while n < 1000 and worst_case_bytes(robot, n + 1, width_px, height_px) <= max_bytes:
        n += 1
    return n
