"""MCAP recordings: frames, readings and intrinsics in one file that Foxglove and ROS 2 tools open.

:mod:`.mcap_format` says what the file holds (pure), :mod:`.mcap_writer` and
:mod:`.mcap_reader` do the I/O, :mod:`.background` is the daemon's writer thread.
The ``mcap`` package is an optional extra (``pip install 'rangebearing[mcap]'``),
imported only when a file is written or read.
"""

from __future__ import annotations

from .mcap_format import CALIBRATION_TOPIC, IMAGE_TOPIC, READINGS_TOPIC
from .mcap_reader import McapRecording, RecordedFrame, RecordedMessage, is_mcap

__all__ = [
    "CALIBRATION_TOPIC",
    "IMAGE_TOPIC",
    "READINGS_TOPIC",
    "McapRecording",
    "RecordedFrame",
    "RecordedMessage",
    "is_mcap",
]
