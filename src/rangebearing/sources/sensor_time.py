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
