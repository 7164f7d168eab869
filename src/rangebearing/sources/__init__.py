"""Frame sources: one :class:`FrameSource` interface, several backends.

``RecordedSource`` (image directories and video files, paced like a camera),
``OpenCVSource`` (USB/V4L2 cameras, files, streams) and ``Picamera2Source``
(the Pi camera; picamera2 is imported only when it is opened). Build the one a
config names with :func:`open_source`.
"""

from __future__ import annotations

from .base import Frame, FrameSource, validate_frame
from .factory import open_source
from .opencv_capture import OpenCVSource
from .picamera2_source import Picamera2Source
from .recorded import RecordedSource, count_recorded, iter_recorded

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
