"""The one interface every frame source implements, and the frame it yields.

A :class:`FrameSource` behaves like a camera: ``read()`` hands back the newest
frame available, counting the ones it had to skip in ``dropped``. Sources are
passed to the daemon and the CLI, never looked up from globals; the recorded
source plays the part of gpiozero's mock pin backend. This module imports no
backend: :mod:`.factory` does the choosing.
"""

from __future__ import annotations

from typing import Callable, Optional, Protocol, runtime_checkable

import cv2
import numpy as np

from .._compat import frozen
from ..core.types import check_frame
from ..core.yuv import Yuv420, yuv420_from_bgr
from ..errors import FrameError


@frozen
class Frame:
    """One camera frame.

    ``image`` is H×W×3 uint8 in OpenCV's BGR order. ``t_mono_ns`` is the capture
    time on CLOCK_MONOTONIC (``time.monotonic_ns()``), the sensor timestamp where
    the source has one. ``index`` is the source's own 0-based frame counter, so a
    gap means frames were dropped upstream. ``name`` is the file name for image
    directories and ``str(index)`` (the position in the file) otherwise.

    ``lores_yuv420`` is the camera's second, YUV420 stream of the same view
    (Picamera2's ``lores``), where the source has one: the pipeline searches
    for bands on it and measures on ``image``.

    ``borrowed``: the arrays are views into the camera's buffers (Picamera2
    read in place), valid only until the source's next ``read()`` or
    ``close()``; whoever keeps them longer (a recorder or view thread) must
    copy them (:func:`kept`). Otherwise they are the consumer's to keep; a
    recorded clip's cached frames are read-only, so one loop cannot alter the
    next.
    """

    image: np.ndarray
    t_mono_ns: int
    index: int
    name: str
    lores_yuv420: Optional[Yuv420] = None
    borrowed: bool = False


def kept(frame: Frame) -> np.ndarray:
    """``frame.image`` safe to keep past the next ``read()``: a copy only when it is borrowed."""
    return frame.image.copy() if frame.borrowed else frame.image


def with_lores(frame: Frame) -> Frame:
    """``frame`` with the YUV420 stream a camera would deliver beside it (OpenCV's I420 of the BGR image).

    For recorded and synthetic sources, so they feed the pipeline as the Pi
    camera does; frames of odd width or height are returned unchanged.
    """
    h, w = frame.image.shape[:2]
    if frame.lores_yuv420 is not None or h % 2 or w % 2:
        return frame
    return Frame(frame.image, frame.t_mono_ns, frame.index, frame.name, yuv420_from_bgr(frame.image),
                 frame.borrowed)


@runtime_checkable
class FrameSource(Protocol):
    """Where frames come from: Picamera2, OpenCV capture, recorded files, synthetic scenes."""

    def open(self) -> None:
        """Start delivering frames; SourceError/CameraError when that is impossible.

        Calling it on a source that is already open does nothing.
        """

    def read(self) -> Optional[Frame]:
        """The newest frame available, or None at the end of the stream.

        Raises FrameError for one bad frame (the next read goes on) and
        SourceError/CameraError when the source has failed.
        """

    def close(self) -> None:
        """Stop and release everything; safe to call twice."""

    @property
    def dropped(self) -> int:
        """Frames that arrived but were overwritten before ``read()`` took them."""


def validate_frame(image: object) -> np.ndarray:
    """Check a decoded image and return it as H×W×3 uint8 BGR.

    Parameters
    ----------
    image : object
        What a decoder or camera produced. Accepted: uint8 arrays of shape
        (H, W) or (H, W, 1) (grey, expanded to BGR), (H, W, 3) (BGR, returned
        as is) and (H, W, 4) (OpenCV BGRA / Picamera2 ``XRGB8888``, whose
        fourth byte is alpha or padding and is dropped). Picamera2's
        ``XBGR8888`` arrives as [R, G, B, X] and must be swapped by the caller;
        no array shape can tell the two apart.

    Returns
    -------
    numpy.ndarray
        (H, W, 3) uint8, C-contiguous.

    Raises
    ------
    FrameError
        ``image`` is None, not an array, empty, not uint8, or of another shape.
    """
    if image is None:
        raise FrameError("no image (the decoder or camera returned None)")
    if isinstance(image, np.ndarray) and image.dtype == np.uint8 and image.size:
        if image.ndim == 3 and image.shape[2] == 1:
            image = image[:, :, 0]
        if image.ndim == 2:
            image = cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_GRAY2BGR)
        elif image.ndim == 3 and image.shape[2] == 4:
            image = image[:, :, :3]
        image = np.ascontiguousarray(image)
    return check_frame(image, min_side_px=1)


Sleep = Callable[[float], object]
