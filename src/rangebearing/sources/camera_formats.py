"""A camera's main stream granted in a format other than 8-bit RGB, read as BGR (picamera2 request.py layouts).

libcamera's ``validate()`` may hand the main stream over in another format than
the RGB888 asked for (a USB camera through picamera2 gives YUYV or MJPEG; a
stand-in may only know YUV420). Each is read as picamera2's
``_make_array_shared`` lays it out (request.py 290-335), or flat as
``make_buffer`` gives it:

* ``YUV420`` / ``YVU420``: (H·3/2, stride), U and V rows of stride/2 bytes; its
  planes are also the search's (the lores stream's layout, at the main size).
* ``NV12`` / ``NV21``: (H·3/2, stride), one plane of interleaved U, V at half height.
* ``YUYV`` / ``YVYU`` / ``UYVY`` / ``VYUY``: (H, stride/2, 2), two pixels in four bytes.
* ``RGB161616`` / ``BGR161616``: (H, W, 3) uint16, byte order as the 8-bit kinds; the high byte is kept.
* ``MJPEG``: decoded (H, W, 3) R, G, B (PIL's order), or the JPEG bytes.

The Y'CbCr kinds are converted with the colour space's matrix (:func:`~rangebearing.core.yuv.yuv_to_bgr`).
An array that does not fit its format is a FrameError (a skipped, counted frame).
"""

from __future__ import annotations

from typing import Callable, Dict, Optional, Tuple

import cv2
import numpy as np

from ..core.yuv import Yuv420, yuv420_planes, yuv_to_bgr
from ..errors import FrameError

Decoded = Tuple[np.ndarray, Optional[Yuv420]]  # the BGR image, and its own YUV420 planes if it has them

_PLANAR = {"YUV420": False, "YVU420": True}  # format -> U and V swapped
_SEMI = {"NV12": False, "NV21": True}
_PACKED = {"YUYV": (0, 1, 3), "YVYU": (0, 3, 1), "UYVY": (1, 0, 2), "VYUY": (1, 2, 0)}  # first Y, U, V byte of 4
_RGB16 = {"RGB161616": slice(0, 3), "BGR161616": slice(2, None, -1)}  # to B, G, R as RGB888 / BGR888 are read
DECODED = frozenset([*_PLANAR, *_SEMI, *_PACKED, *_RGB16, "MJPEG"])


def _rows(array: np.ndarray, rows: int, min_bytes: int) -> np.ndarray:
    """The buffer as ``rows`` rows of bytes (its stride), whatever shape it came in."""
    if not isinstance(array, np.ndarray) or array.size == 0:
        raise FrameError(f"no image data ({type(array).__name__})")
    raw = array if array.dtype == np.uint8 else np.ascontiguousarray(array).view(np.uint8)
    if raw.ndim == 2 and raw.shape[0] == rows:
        buf = raw
    else:
        flat = np.ascontiguousarray(raw).reshape(-1)
        if flat.size % rows:
            raise FrameError(f"a {array.dtype} {array.shape} buffer is not {rows} rows of bytes")
        buf = flat.reshape(rows, -1)
    if buf.shape[1] < min_bytes:
        raise FrameError(f"rows of {buf.shape[1]} bytes, fewer than the {min_bytes} of one row of pixels")
    return buf


def _full(half: np.ndarray, w: int, h: int) -> np.ndarray:
    return cv2.resize(np.ascontiguousarray(half), (w, h), interpolation=cv2.INTER_LINEAR)


def _planar(array: np.ndarray, w: int, h: int, space: str, swap: bool) -> Decoded:
    buf = _rows(array, h * 3 // 2, w)
    yuv = yuv420_planes(buf, w, h, space)
    if swap:
        yuv = Yuv420(yuv.y, yuv.v, yuv.u, space)
    return yuv_to_bgr(yuv.y, _full(yuv.u, w, h), _full(yuv.v, w, h), space), yuv


def _semi(array: np.ndarray, w: int, h: int, space: str, swap: bool) -> Decoded:
    buf = _rows(array, h * 3 // 2, w)
    uv = buf[h: h + h // 2, : w // 2 * 2].reshape(h // 2, w // 2, 2)
    u, v = (uv[..., 1], uv[..., 0]) if swap else (uv[..., 0], uv[..., 1])
    yuv = Yuv420(buf[:h, :w], np.ascontiguousarray(u), np.ascontiguousarray(v), space)
    return yuv_to_bgr(yuv.y, _full(yuv.u, w, h), _full(yuv.v, w, h), space), yuv


def _packed(order: Tuple[int, int, int]) -> Callable[[np.ndarray, int, int, str], Decoded]:
    y0, uo, vo = order

    def read(array: np.ndarray, w: int, h: int, space: str) -> Decoded:
        quads = _rows(array, h, 2 * w)[:, : w // 2 * 4].reshape(h, w // 2, 4)
        y = quads[..., [y0, y0 + 2]].reshape(h, w // 2 * 2)
        u = np.repeat(quads[..., uo], 2, axis=1)
        v = np.repeat(quads[..., vo], 2, axis=1)
        return yuv_to_bgr(y, u, v, space), None

    return read


def _rgb16(channels: slice) -> Callable[[np.ndarray, int, int, str], Decoded]:
    def read(array: np.ndarray, w: int, h: int, space: str) -> Decoded:
        if isinstance(array, np.ndarray) and array.dtype == np.uint16 and array.shape[:1] == (h,) and array.ndim == 3:
            words = array[:, :w, :3]
        else:
            words = np.ascontiguousarray(_rows(array, h, 6 * w)[:, : 6 * w]).view("<u2").reshape(h, w, 3)
        return np.ascontiguousarray((words[..., channels] >> 8).astype(np.uint8)), None

    return read


def _mjpeg(array: np.ndarray, w: int, h: int, space: str) -> Decoded:
    if isinstance(array, np.ndarray) and array.ndim == 3 and array.shape[2] == 3 and array.dtype == np.uint8:
        return np.ascontiguousarray(array[..., ::-1]), None  # picamera2 decodes with PIL: R, G, B
    if not isinstance(array, np.ndarray) or array.size == 0:
        raise FrameError("no MJPEG data")
    image = cv2.imdecode(np.ascontiguousarray(array).reshape(-1).view(np.uint8), cv2.IMREAD_COLOR)
    if image is None:
        raise FrameError(f"an MJPEG frame of {array.nbytes} bytes does not decode")
    return image, None


_READERS: Dict[str, Callable[[np.ndarray, int, int, str], Decoded]] = {
    **{f: (lambda a, w, h, s, _swap=swap: _planar(a, w, h, s, _swap)) for f, swap in _PLANAR.items()},
    **{f: (lambda a, w, h, s, _swap=swap: _semi(a, w, h, s, _swap)) for f, swap in _SEMI.items()},
    **{f: _packed(order) for f, order in _PACKED.items()},
    **{f: _rgb16(channels) for f, channels in _RGB16.items()},
    "MJPEG": _mjpeg,
}


def decode_main(array: np.ndarray, fmt: str, width_px: int, height_px: int, colour_space: str) -> Decoded:
    """The main stream in ``fmt`` (one of :data:`DECODED`) as BGR uint8, and its YUV420 planes if it is planar.

    Raises
    ------
    FrameError
        The buffer does not hold a ``width_px`` × ``height_px`` image in ``fmt``.
    """
    try:
        return _READERS[fmt](array, int(width_px), int(height_px), colour_space)
    except FrameError:
        raise
    except (ValueError, TypeError, IndexError, cv2.error) as exc:
        raise FrameError(f"a {fmt} main stream that cannot be read: {exc}") from exc
