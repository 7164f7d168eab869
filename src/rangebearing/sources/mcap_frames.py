"""Frames from an MCAP recording (``/camera/image``), for the recorded source and ``replay``.

A frame is named by its 0-based position in the file, as a video frame is;
its capture time is kept too (:func:`frame_times_ns`), so ground truth may be
keyed by either (see :func:`rangebearing.evaluation.truth.key_by_position`).
A file cut short plays up to its last complete chunk.
"""

from __future__ import annotations

import os
import struct
from typing import Any, Dict, Iterator, List, Optional, Tuple, Union

import numpy as np

from ..errors import MissingExtraError, RecordingError, SourceError

PathLike = Union[str, "os.PathLike[str]"]


def _recording(path: PathLike) -> Any:
    from ..recording.mcap_reader import McapRecording

    try:
        return McapRecording(path)
    except RecordingError as exc:
        raise SourceError(str(exc)) from None


def is_mcap_file(path: PathLike) -> bool:
    """True for an existing file that starts with the MCAP magic."""
    from ..recording.mcap_reader import MAGIC

    try:
        with open(path, "rb") as f:
            return f.read(len(MAGIC)) == MAGIC
    except OSError:
        return False


def iter_mcap(path: PathLike, reasons: Optional[Dict[str, str]] = None) -> Iterator[Tuple[str, Optional[np.ndarray]]]:
    """Yield ``(str(position), image)`` per frame; an undecodable one as ``(name, None)``, its reason in ``reasons``."""
    try:
        for frame in _recording(path).frames():
            if frame.image is None and reasons is not None:
                reasons[str(frame.position)] = frame.why
            yield str(frame.position), frame.image
    except MissingExtraError as exc:
        raise SourceError(str(exc)) from None


def count_mcap(path: PathLike) -> Optional[int]:
    """The frame count from the file's summary, or ``None`` (no summary: a file cut short)."""
    try:
        from mcap.exceptions import McapError
        from mcap.reader import make_reader
    except ImportError:
        return None
    from ..recording.mcap_format import IMAGE_TOPIC

    try:
        with open(path, "rb") as f:
            summary = make_reader(f).get_summary()
    except (McapError, OSError, ValueError, struct.error):  # damage only means "unknown": reading says more
        return None
    if summary is None or summary.statistics is None:
        return None
    ids = [c.id for c in summary.channels.values() if c.topic == IMAGE_TOPIC]
    return sum(summary.statistics.channel_message_counts.get(i, 0) for i in ids)


def frame_times_ns(path: PathLike) -> List[int]:
    """Every frame's capture time (Unix ns), by position."""
    return _recording(path).frame_times_ns()


class McapFrames:
    """Sequential access to a recording's frames; seeking backwards starts the file again."""

    def __init__(self, path: PathLike, end: Any) -> None:
        self._path = path
        self._end = end
        _recording(path)  # fails now for a file that is not MCAP
        self._frames: Optional[Iterator[Any]] = None
        self._pos = 0  # position of the frame the iterator yields next
        self.length: Optional[int] = None  # learned when the end is reached
        self._why: Tuple[int, Any] = (-1, "")  # the last undecodable frame: position, its message (or reason)

    def name(self, pos: int) -> str:
        return str(pos)

    def why(self, pos: int) -> str:
        """Why the frame at ``pos`` (the last one :meth:`get` gave as ``None``) gives no image."""
        from ..recording.mcap_reader import why_image_undecodable

        return why_image_undecodable(self._why[1]) if self._why[0] == pos else "the recording's image does not decode"

    def get(self, pos: int) -> Any:
        from ..recording.mcap_reader import decode_image

        if self._frames is None or pos < self._pos:
            self._frames = _recording(self._path).images()
            self._pos = 0
        for position, _index, img in self._frames:
            self._pos += 1
            if position == pos:
                image = None if isinstance(img, str) else decode_image(img)
                if image is None:
                    self._why = (pos, img)
                return image
        self.length = self._pos
        return self._end

    def close(self) -> None:
        self._frames = None
