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
from .camera_capture import Notes
from .camera_formats import DECODED, decode_main

_log = logging.getLogger(__name__)


class Held:
    """One completed request and the streams mapped from it; :meth:`release` gives them all back.

    ``mapped`` is ``picamera2.MappedArray``, or None for a picamera2 without
    it, when :meth:`array` falls back to ``make_array``'s copy.
    """

    def __init__(self, request: Any, mapped: Any, notes: Notes) -> None:
        self.request = request
        self._mapped = mapped
        self._maps: List[Any] = []
        self._notes = notes

    def array(self, stream: str) -> np.ndarray:
        """The stream's buffer: in place (kept mapped until :meth:`release`) or copied.

        A ``MappedArray`` that cannot map (an older signature without ``write``,
        a stand-in that fails) falls back to ``make_array``; so does every later
        frame (:attr:`mapped` is then None).
        """
        if self._mapped is not None:
            try:
                try:
                    m = self._mapped(self.request, stream, write=False)
                except TypeError:  # a MappedArray(request, stream) without the write flag
                    m = self._mapped(self.request, stream)
                m.__enter__()
            except Exception as exc:  # any failure to map: copy instead, and say so once
                self._notes.once("map", "MappedArray failed (%s): copying frames with make_array", exc)
                self._mapped = None
            else:
                self._maps.append(m)
                array = getattr(m, "array", None)
                if array is not None:
                    return array
        try:
            return self.request.make_array(stream)
        except Exception as exc:  # a format make_array cannot shape ("Format NV12 not supported"): its bytes
            make_buffer = getattr(self.request, "make_buffer", None)
            if make_buffer is None:
                raise
            self._notes.once("buffer-" + stream, "make_array(%r) failed (%s): reading its bytes with make_buffer",
                             stream, exc)
            return make_buffer(stream)

    @property
    def mapped(self) -> Any:
        """``MappedArray`` if it worked for this request (or was not tried yet), else None."""
        return self._mapped

    def release(self) -> None:
        """Unmap every stream and release the request; failures are logged, never raised."""
        for m in self._maps:
            try:
                m.__exit__(None, None, None)
            except Exception as exc:  # keep going: the buffer must go back to the camera
                self._notes.once("unmap", "unmapping failed: %s", exc)
        self._maps = []
        try:
            self.request.release()
        except Exception as exc:  # deliberately broad: a release that fails must not end the frame loop
            self._notes.once("release", "release failed: %s", exc)


class ArrayRequest:
    """A request stand-in around one ``capture_array`` result (a picamera2 without ``capture_request``)."""

    def __init__(self, main: np.ndarray) -> None:
        self._main = main

    def make_array(self, stream: str) -> np.ndarray:
        if stream != "main":
            raise KeyError(stream)
        return self._main

    def get_metadata(self) -> Dict[str, Any]:
        return {}  # no SensorTimestamp: the frame is stamped when it arrived

    def release(self) -> None:
        pass


# picamera2's byte orders (the manual's "Image formats"; request.py's _make_array_shared gives (H, W, C)):
# RGB888 is [B, G, R], BGR888 [R, G, B], XBGR8888 [R, G, B, 255], XRGB8888 [B, G, R, 255]
_TO_BGR = {"RGB888": slice(0, 3), "XRGB8888": slice(0, 3), "BGR888": slice(2, None, -1),
           "XBGR8888": slice(2, None, -1)}
# the lores stream's Y'CbCr matrix, by libcamera.ColorSpace's ycbcrEncoding and range
_MATRICES = {("Rec601", "Limited"): "smpte170m", ("Rec709", "Limited"): "rec709", ("Rec601", "Full"): "sycc"}
_NAMED = {"smpte170m": "smpte170m", "rec709": "rec709", "sycc": "sycc"}  # libcamera ColorSpace::toString()


class Layout:
    """How to read the streams libcamera granted: the main stream's channels as B, G, R; the lores planes.

    Built by :func:`granted` from ``camera_configuration()`` after ``configure()``,
    whose sizes, formats and colour space may differ from what was asked.
    """

    def __init__(self, width_px: int, channels: slice, lores_size: Optional[Tuple[int, int]], swap_uv: bool,
                 colour_space: str, camera_num: int, height_px: int = 0, bytes_per_px: int = 3,
                 main_format: str = "RGB888") -> None:
        self.width_px, self.channels = width_px, channels
        self.height_px, self.bytes_per_px = height_px, bytes_per_px
        self.lores_size, self.swap_uv, self.colour_space = lores_size, swap_uv, colour_space
        self.main_format = main_format  # one of _TO_BGR (read in place) or camera_formats.DECODED (converted)
        self._camera_num = camera_num
        self._warned = False

    def main(self, array: Any) -> Tuple[Any, Optional[Yuv420]]:
        """The main stream as B, G, R, and its own YUV420 planes if it is YUV420 (else None).

        FrameError if a main stream granted in a converted format cannot be read.
        """
        if self.main_format in DECODED:
            return decode_main(array, self.main_format, self.width_px, self.height_px, self.colour_space)
        return self.bgr(array), None

    def bgr(self, array: Any) -> Any:
        """The main stream's pixels as B, G, R (a view; padding columns of an old ``make_array`` cut off).

        A buffer handed over flat (rows of ``stride`` bytes, or one run of bytes, as
        ``make_buffer`` gives it) is shaped as (H, W, C) first.
        """
        if isinstance(array, np.ndarray) and array.ndim < 3 and array.dtype == np.uint8:
            array = self._shaped(array)
        if isinstance(array, np.ndarray) and array.ndim == 3:
            return array[:, : self.width_px, self.channels]
        return array  # validate_frame words what is wrong with it

    def _shaped(self, flat: np.ndarray) -> np.ndarray:
        h, w, c = self.height_px, self.width_px, self.bytes_per_px
        if h <= 0 or flat.size < h * w * c or flat.size % h:
            return flat
        rows = flat.reshape(h, -1) if flat.flags.c_contiguous or flat.ndim == 2 else flat
        if rows.ndim != 2 or rows.shape[1] < w * c:
            return flat
        return rows[:, : w * c].reshape(h, w, c)

    def planes(self, buffer: Optional[np.ndarray]) -> Optional[Yuv420]:
        """The Y, U, V planes of a lores buffer (views), or None: then the main image is searched instead."""
        if buffer is None or self.lores_size is None:
            return None
        w, h = self.lores_size
        if isinstance(buffer, np.ndarray) and buffer.ndim == 1 and h > 1 and buffer.size % (h * 3 // 2) == 0:
            buffer = buffer.reshape(h * 3 // 2, -1)  # make_buffer's one run of bytes: rows of its stride
        try:
            yuv = yuv420_planes(buffer, w, h, self.colour_space)
        except (ValueError, TypeError, AttributeError) as exc:  # an odd buffer: say so once, search the main image
            if not self._warned:
                _log.warning("camera %d: lores stream unusable, searching the main image: %s", self._camera_num, exc)
                self._warned = True
            return None
        return Yuv420(yuv.y, yuv.v, yuv.u, yuv.colour_space) if self.swap_uv else yuv


def granted(active: Dict[str, Any], camera_num: int) -> Layout:
    """The :class:`Layout` of a configured camera; CameraError if its main stream is in no colour format we read."""
    main = active["main"]
    fmt = str(main.get("format", "RGB888"))
    if fmt not in _TO_BGR and fmt not in DECODED:
        raise CameraError(f"camera {camera_num}: the camera gives its main stream as {fmt!r}, not one of "
                          f"{', '.join([*_TO_BGR, *sorted(DECODED)])} (not a Raspberry Pi camera? use "
                          "source.kind: opencv)")
    if "colour_space" in active:
        matrix = _matrix(active["colour_space"])
    else:  # not reported: picamera2's video default (create_video_configuration), by the main size
        big = int(main["size"][0]) >= 1280 and int(main["size"][1]) >= 720
        matrix = "rec709" if big else "smpte170m"
    lores = active.get("lores")
    size, swap = None, False
    if lores:
        lores_fmt = str(lores.get("format"))
        same_size = [int(v) for v in lores.get("size", ())] == [int(v) for v in main["size"]]
        if not same_size:  # the search reads the lores planes at the main image's scale (its U, V at half)
            _log.warning("camera %d: lores stream granted at %s, not the main stream's %s: searching the main "
                         "image instead", camera_num, lores.get("size"), main["size"])
        elif lores_fmt not in ("YUV420", "YVU420") or matrix is None:
            _log.warning("camera %d: lores stream granted as %s in colour space %s, which the search cannot read: "
                         "searching the main image instead", camera_num, lores_fmt, active.get("colour_space"))
        else:
            size, swap = (int(lores["size"][0]), int(lores["size"][1])), lores_fmt == "YVU420"
    if matrix is None:  # a colour space we do not know: the usual one (only a Y'CbCr main stream is read with it)
        matrix = "smpte170m"
    return Layout(int(main["size"][0]), _TO_BGR.get(fmt, slice(0, 3)), size, swap, matrix, camera_num,
                  int(main["size"][1]), 4 if fmt.startswith("X") else 3, fmt)


def _matrix(colour_space: Any) -> Optional[str]:
    """Our name for a libcamera.ColorSpace's Y'CbCr matrix and range, or None if it is none we know.

    Read from its ``ycbcrEncoding`` / ``range`` (libcamera enums: their ``name``;
    plain strings in a stand-in), else from its name (``str()``: "SMPTE170M").
    """
    def name(value: Any) -> Any:
        return value if isinstance(value, str) else getattr(value, "name", None)

    matrix = _MATRICES.get((name(getattr(colour_space, "ycbcrEncoding", None)),
                            name(getattr(colour_space, "range", None))))
    if colour_space is None:
        return None
    return matrix or _NAMED.get(str(colour_space).lower())


def copied(search: Optional[Yuv420]) -> Optional[Yuv420]:
    """Planes that own their memory (for a frame the caller keeps past the request)."""
    if search is None:
        return None
    return Yuv420(search.y.copy(), search.u.copy(), search.v.copy(), search.colour_space)
