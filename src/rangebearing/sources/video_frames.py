"""A video file as random access frames for the recorded source: sequential reads, seeking back reopens."""

from __future__ import annotations

from pathlib import Path
from typing import Optional, Union

import cv2
import numpy as np

from ..errors import SourceError


def open_video(path: Path) -> cv2.VideoCapture:
    """The capture of a video file; SourceError when OpenCV cannot open it."""
    cap = cv2.VideoCapture(str(path))
    if not cap.isOpened():
        cap.release()
        raise SourceError(f"{path}: OpenCV cannot open this as a video")
    return cap


class EndOfVideo:
    """Returned by a reader asked for a position past the end."""


END = EndOfVideo()
Fetched = Union[Optional[np.ndarray], EndOfVideo]


class VideoFrames:
    """Sequential access to a video; seeking backwards reopens, skipping grabs."""

    def __init__(self, path: Path) -> None:
        self._path = path
        self._cap: Optional[cv2.VideoCapture] = open_video(path)
        self._pos = 0  # position of the frame the capture returns next
        self.length: Optional[int] = None  # learned when the end is reached

    def name(self, pos: int) -> str:
        return str(pos)

    def why(self, pos: int) -> str:
        """Why frame ``pos`` gives no image (a video's decoder never gives one short of its end)."""
        return "the video's decoder gives no image"

    def get(self, pos: int) -> Fetched:
        if self._cap is None or pos < self._pos:
            self.close()
            self._cap = open_video(self._path)
            self._pos = 0
        while self._pos < pos:
            if not self._cap.grab():
                self.length = self._pos
                return END
            self._pos += 1
        ok, image = self._cap.read()
        if not ok:
            self.length = pos
            return END
        self._pos += 1
        return image

    def close(self) -> None:
        if self._cap is not None:
            self._cap.release()
            self._cap = None
