"""A camera request's buffers read in place, and given back together (Picamera2's ``MappedArray``).

``make_array`` copies a whole frame out of camera memory; ``MappedArray``
(picamera2 request.py) maps the buffer and shapes it without a copy, valid
while the mapping is entered and the request not released. :class:`Held`
keeps both for as long as the frame is in use.
"""

from __future__ import annotations

import logging
from typing import Any, List, Optional

import numpy as np

from ..core.yuv import Yuv420, yuv420_planes

_log = logging.getLogger(__name__)


class Held:
    """One completed request and the streams mapped from it; :meth:`release` gives them all back.

    ``mapped`` is ``picamera2.MappedArray``, or None for a picamera2 without
    it, when :meth:`array` falls back to ``make_array``'s copy.
    """

    def __init__(self, request: Any, mapped: Any, camera_num: int) -> None:
        self.request = request
        self._mapped = mapped
        self._maps: List[Any] = []
        self._camera_num = camera_num

    def array(self, stream: str) -> np.ndarray:
        """The stream's buffer: in place (kept mapped until :meth:`release`) or copied."""
        if self._mapped is None:
            return self.request.make_array(stream)
        m = self._mapped(self.request, stream, write=False)
        m.__enter__()
        self._maps.append(m)
        return m.array

    def release(self) -> None:
        """Unmap every stream and release the request; failures are logged, never raised."""
        for m in self._maps:
            try:
                m.__exit__(None, None, None)
            except Exception as exc:  # keep going: the buffer must go back to the camera
                _log.warning("camera %d: unmapping failed: %s", self._camera_num, exc)
        self._maps = []
        try:
            self.request.release()
        except RuntimeError as exc:
            _log.warning("camera %d: release failed: %s", self._camera_num, exc)


def lores_planes(buffer: Optional[np.ndarray], size: Optional[tuple], camera_num: int) -> Optional[Yuv420]:
    """The Y, U, V planes of a lores YUV420 buffer of ``size`` (SMPTE 170M), or None if unusable."""
    if buffer is None or size is None:
        return None
    try:
        return yuv420_planes(buffer, size[0], size[1], "smpte170m")
    except ValueError as exc:  # an odd buffer: the main image is searched instead
        _log.debug("camera %d: lores unusable: %s", camera_num, exc)
        return None


def copied(search: Optional[Yuv420]) -> Optional[Yuv420]:
    """Planes that own their memory (for a frame the caller keeps past the request)."""
    if search is None:
        return None
    return Yuv420(search.y.copy(), search.u.copy(), search.v.copy(), search.colour_space)
