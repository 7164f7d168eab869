"""Sensor timestamps on the monotonic clock, and frames lost between them (the Pi camera's ``SensorTimestamp``)."""

from __future__ import annotations

import time
from typing import Optional


def sensor_to_monotonic_ns(sensor_ns: int, received_ns: int, boot_offset_ns: int) -> int:
    """Put a ``SensorTimestamp`` on CLOCK_MONOTONIC.

    libcamera's control_ids_core.yaml documents SensorTimestamp as CLOCK_BOOTTIME,
    but the Pi pipeline copies the V4L2 buffer timestamp (CLOCK_MONOTONIC) and
    picamera2 itself compares it with ``time.monotonic_ns()`` (``capture_request(
    flush=...)`` in picamera2.py). The two clocks differ only by time spent in
    suspend (``boot_offset_ns`` = BOOTTIME − MONOTONIC). A frame is always
    exposed before it is received, so a stamp later than ``received_ns`` must be
    BOOTTIME; if even the converted stamp is in the future, use ``received_ns``.
    """
    if sensor_ns <= received_ns:
        return sensor_ns
    converted = sensor_ns - boot_offset_ns
    return converted if converted <= received_ns else received_ns


MAX_LAG_NS = 5_000_000_000  # a stamp this much older than its frame's arrival is on no clock of ours


class SensorClock:
    """``SensorTimestamp`` put on CLOCK_MONOTONIC, also when it is on no clock we know.

    A stamp on CLOCK_MONOTONIC (or BOOTTIME) lies at most :data:`MAX_LAG_NS`
    before its frame arrived. Anything else (a stand-in counting from 0, a
    clock of its own) keeps its spacing, which the rate filters and the drop
    count use, shifted so that the first such frame is stamped when it
    arrived; the shift is learnt again when the stamps jump away from the
    arrivals, and no frame is ever stamped after it arrived.
    """

    def __init__(self, boot_offset_ns: int) -> None:
        self.boot_offset_ns = boot_offset_ns
        self._shift_ns: Optional[int] = None

    def to_monotonic_ns(self, sensor_ns: int, received_ns: int) -> int:
        for t in (sensor_ns, sensor_ns - self.boot_offset_ns):  # MONOTONIC (the Pi's), else BOOTTIME
            if received_ns - MAX_LAG_NS <= t <= received_ns:
                return t
        shift = self._shift_ns
        if shift is None or abs(sensor_ns + shift - received_ns) > MAX_LAG_NS:
            shift = self._shift_ns = received_ns - sensor_ns
        return min(sensor_ns + shift, received_ns)


def frames_missed(prev_ns: Optional[int], sensor_ns: int, period_ns: float) -> int:
    """Frames lost between two sensor timestamps ``period_ns`` apart (0 for the first)."""
    if prev_ns is None or period_ns <= 0:
        return 0
    return max(0, round((sensor_ns - prev_ns) / period_ns) - 1)


def boot_offset_ns() -> int:
    """CLOCK_BOOTTIME − CLOCK_MONOTONIC now: the time spent in suspend (0 where there is no BOOTTIME)."""
    boottime = getattr(time, "CLOCK_BOOTTIME", None)
    if boottime is None:
        return 0
    return time.clock_gettime_ns(boottime) - time.monotonic_ns()
