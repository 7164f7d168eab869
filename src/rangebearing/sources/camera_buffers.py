"""A camera request's buffers read in place, and given back together (Picamera2's ``MappedArray``).

``make_array`` copies a whole frame out of camera memory; ``MappedArray``
(picamera2 request.py) maps the buffer and shapes it without a copy, valid
while the mapping is entered and the request not released. :class:`Held`
keeps both for as long as the frame is in use.
"""

from __future__ import annotations

import logging
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from ..core.yuv import Yuv420, yuv420_planes
from ..errors import CameraError

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


# picamera2's byte orders (the manual's "Image formats"; request.py's _make_array_shared gives (H, W, C)):
# RGB888 is [B, G, R], BGR888 [R, G, B], XBGR8888 [R, G, B, 255], XRGB8888 [B, G, R, 255]
_TO_BGR = {"RGB888": slice(0, 3), "XRGB8888": slice(0, 3), "BGR888": slice(2, None, -1),
           "XBGR8888": slice(2, None, -1)}
# the lores stream's Y'CbCr matrix, by libcamera.ColorSpace's ycbcrEncoding and range
_MATRICES = {("Rec601", "Limited"): "smpte170m", ("Rec709", "Limited"): "rec709", ("Rec601", "Full"): "sycc"}


class Layout:
    """How to read the streams libcamera granted: the main stream's channels as B, G, R; the lores planes.

    Built by :func:`granted` from ``camera_configuration()`` after ``configure()``,
    whose sizes, formats and colour space may differ from what was asked.
    """

    def __init__(self, width_px: int, channels: slice, lores_size: Optional[Tuple[int, int]], swap_uv: bool,
                 colour_space: str, camera_num: int) -> None:
        self.width_px, self.channels = width_px, channels
        self.lores_size, self.swap_uv, self.colour_space = lores_size, swap_uv, colour_space
        self._camera_num = camera_num
        self._warned = False

    def bgr(self, array: Any) -> Any:
        """The main stream's pixels as B, G, R (a view; padding columns of an old ``make_array`` cut off)."""
        if isinstance(array, np.ndarray) and array.ndim == 3:
            return array[:, : self.width_px, self.channels]
        return array  # validate_frame words what is wrong with it

    def planes(self, buffer: Optional[np.ndarray]) -> Optional[Yuv420]:
        """The Y, U, V planes of a lores buffer (views), or None: then the main image is searched instead."""
        if buffer is None or self.lores_size is None:
            return None
        try:
            yuv = yuv420_planes(buffer, self.lores_size[0], self.lores_size[1], self.colour_space)
        except ValueError as exc:  # an odd buffer: say so once, then search the main image
            if not self._warned:
                _log.warning("camera %d: lores stream unusable, searching the main image: %s", self._camera_num, exc)
                self._warned = True
            return None
        return Yuv420(yuv.y, yuv.v, yuv.u, yuv.colour_space) if self.swap_uv else yuv


def granted(active: Dict[str, Any], camera_num: int) -> Layout:
    """The :class:`Layout` of a configured camera; CameraError if its main stream is not RGB in some order."""
    main = active["main"]
    fmt = str(main.get("format", "RGB888"))
    if fmt not in _TO_BGR:
        raise CameraError(f"camera {camera_num}: the camera gives its main stream as {fmt!r}, not one of "
                          f"{', '.join(_TO_BGR)} (not a Raspberry Pi camera? use source.kind: opencv)")
    lores = active.get("lores")
    size, swap, matrix = None, False, "smpte170m"
    if lores:
        lores_fmt, matrix = str(lores.get("format")), _matrix(active.get("colour_space"))
        if lores_fmt not in ("YUV420", "YVU420") or matrix is None:
            _log.warning("camera %d: lores stream granted as %s in colour space %s, which the search cannot read: "
                         "searching the main image instead", camera_num, lores_fmt, active.get("colour_space"))
            matrix = "smpte170m"
        else:
            size, swap = (int(lores["size"][0]), int(lores["size"][1])), lores_fmt == "YVU420"
    return Layout(int(main["size"][0]), _TO_BGR[fmt], size, swap, matrix, camera_num)


def _matrix(colour_space: Any) -> Optional[str]:
    """Our name for a libcamera.ColorSpace's Y'CbCr matrix and range, or None if it is none we know."""
    encoding = getattr(getattr(colour_space, "ycbcrEncoding", None), "name", None)
    full = getattr(getattr(colour_space, "range", None), "name", None)
    return _MATRICES.get((encoding, full))


def copied(search: Optional[Yuv420]) -> Optional[Yuv420]:
    """Planes that own their memory (for a frame the caller keeps past the request)."""
    if search is None:
        return None
    return Yuv420(search.y.copy(), search.u.copy(), search.v.copy(), search.colour_space)
