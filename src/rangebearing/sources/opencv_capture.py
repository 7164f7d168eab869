"""OpenCV capture: a USB/V4L2 camera, a video file or a network stream.

A grabber thread owns the ``cv2.VideoCapture`` and keeps only the newest frame,
so a slow consumer gets the latest image instead of a growing backlog (frames it
never saw are counted in ``dropped``). A plain video file is not live: there the
grabber waits for each frame to be taken, so every frame is delivered.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from typing import Callable, Optional, Union

import cv2

from ..errors import FrameError, SourceError
from .base import Frame, validate_frame
from .faults import TimeoutBudget

_log = logging.getLogger(__name__)


def _capture_target(device: str) -> Union[int, str]:
    """A camera index for "0", "1"…; the path or URL otherwise."""
    text = device.strip()
    return int(text) if text.isdigit() else text


class OpenCVSource:
    """Frames from ``cv2.VideoCapture(device)``.

    ``device`` is a camera index ("0"), a ``/dev/videoN`` path, a video file or
    a stream URL. ``read()`` waits up to ``timeout_s`` for a frame it has not
    returned before; a timeout raises FrameError, and the ``retries``-th timeout
    in a row raises CameraError. The end of a file or stream gives None.
    """

    def __init__(
        self,
        device: str,
        width: int = 640,
        height: int = 480,
        fps: float = 30.0,
        *,
        timeout_s: float = 2.0,
        retries: int = 5,
        clock: Callable[[], int] = time.monotonic_ns,
    ) -> None:
        self._device = str(device)
        self._width = width
        self._height = height
        self._fps = fps
        self._timeout_s = timeout_s
        self._budget = TimeoutBudget(str(device), timeout_s, retries)
        self._clock = clock
        self._live = not os.path.isfile(self._device)
        self._cond = threading.Condition()
        self._thread: Optional[threading.Thread] = None
        self._stop = threading.Event()
        self._latest: Union[Frame, FrameError, None] = None
        self._ended = False
        self._failure: Optional[SourceError] = None
        self._dropped = 0
        self._budget.frame_arrived()

    @property
    def dropped(self) -> int:
        return self._dropped

    def open(self) -> None:
        """Open the capture and start the grabber thread; SourceError if OpenCV cannot."""
        if self._thread is not None:
            return
        cap = cv2.VideoCapture(_capture_target(self._device))
        if not cap.isOpened():
            cap.release()
            raise SourceError(f"OpenCV cannot open {self._device!r}")
        if self._live:
            # Requests only: a camera may pick the nearest mode it supports.
            cap.set(cv2.CAP_PROP_FRAME_WIDTH, self._width)
            cap.set(cv2.CAP_PROP_FRAME_HEIGHT, self._height)
            if self._fps > 0:
                cap.set(cv2.CAP_PROP_FPS, self._fps)
        # A fresh stop event per grabber: one left blocked by an earlier close()
        # must never be revived by this open().
        self._stop = threading.Event()
        self._ended = False
        self._failure = None
        self._thread = threading.Thread(
            target=self._grab_loop, args=(cap, self._stop),
            name=f"opencv-grab-{self._device}", daemon=True,
        )
        self._thread.start()

    def _grab_loop(self, cap: cv2.VideoCapture, stop: threading.Event) -> None:
        index = 0
        try:
            while not stop.is_set():
                try:
                    ok, image = cap.read()
                except cv2.error as exc:
                    if not stop.is_set():
                        self._finish(SourceError(f"{self._device}: capture failed: {exc}"))
                    return
                t_ns = self._clock()
                if stop.is_set():
                    return
                if not ok:
                    self._finish(None)
                    return
                item: Union[Frame, FrameError]
                try:
                    item = Frame(validate_frame(image), t_ns, index, str(index))
                except FrameError as exc:
                    item = FrameError(f"{self._device} frame {index}: {exc}")
                index += 1
                with self._cond:
                    if not self._live:
                        self._cond.wait_for(lambda: self._latest is None or stop.is_set())
                    if stop.is_set():
                        return
                    if self._latest is not None:
                        self._dropped += 1
                    self._latest = item
                    self._cond.notify_all()
        finally:
            cap.release()  # the thread owns the capture: never released under a blocked read()

    def _finish(self, failure: Optional[SourceError]) -> None:
        with self._cond:
            self._ended = True
            self._failure = failure
            self._cond.notify_all()

    def read(self) -> Optional[Frame]:
        """The newest frame not yet returned; None once the stream has ended."""
        if self._thread is None:
            raise SourceError(f"OpenCV source {self._device!r} is not open")
        with self._cond:
            ready = self._cond.wait_for(
                lambda: self._latest is not None or self._ended, timeout=self._timeout_s
            )
            item, self._latest = self._latest, None
            self._cond.notify_all()
            ended, failure = self._ended, self._failure
        if item is not None:
            self._budget.frame_arrived()
            if isinstance(item, FrameError):
                raise item
            return item
        if failure is not None:
            raise failure
        if ended or ready:
            return None
        raise self._budget.timed_out()

    def close(self) -> None:
        """Stop the grabber; waits briefly for it, never forever (a network read can block)."""
        thread, self._thread = self._thread, None
        if thread is None:
            return
        self._stop.set()
        with self._cond:
            self._cond.notify_all()
        thread.join(timeout=self._timeout_s)
        if thread.is_alive():
            _log.warning("grabber for %s still blocked in read(); leaving it to exit on its own",
                         self._device)
        with self._cond:
            self._latest = None
