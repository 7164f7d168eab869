"""Frame sources: one :class:`FrameSource` interface, several backends.

``RecordedSource`` (image directories and video files, paced like a camera),
``OpenCVSource`` (USB/V4L2 cameras, files, streams) and ``Picamera2Source``
(the Pi camera; picamera2 is imported only when it is opened). Build the one a
config names with :func:`open_source`. The backends are imported on first use,
so the daemon loads only the one it runs (start-up time).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._compat import lazy_attributes
from .base import Frame, FrameSource, validate_frame

_LAZY = {
    "open_source": ".factory", "OpenCVSource": ".opencv_capture", "Picamera2Source": ".picamera2_source",
    "RecordedSource": ".recorded", "count_recorded": ".recorded", "iter_recorded": ".recorded",
}

if TYPE_CHECKING:
    from .factory import open_source
    from .opencv_capture import OpenCVSource
    from .picamera2_source import Picamera2Source
    from .recorded import RecordedSource, count_recorded, iter_recorded


__getattr__ = lazy_attributes(__name__, _LAZY)


__all__ = [
    "Frame",
    "FrameSource",
    "OpenCVSource",
    "Picamera2Source",
    "RecordedSource",
    "count_recorded",
    "iter_recorded",
    "open_source",
    "validate_frame",
]
