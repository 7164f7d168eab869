"""The daemon's recorder: an MCAP writer on its own thread, bounded in size, never in the way.

The capture loop only hands over references (``put_nowait`` on a bounded queue):
encoding PNG/JPEG and writing happen on the writer thread. When the queue is full
the item is dropped and counted. When the file reaches ``max_bytes`` it is
**rotated**: finished (footer and index written), renamed to ``NAME.1.mcap``
(replacing the previous one) and a fresh ``NAME.mcap`` started, so the disk holds
at most about twice ``max_bytes`` and always the most recent stretch. A write
error (a full disk, a removed USB stick) stops the recording, is logged once and
counted; the capture loop and the publishers go on.
"""

from __future__ import annotations

import contextlib
import logging
import os
import queue
import threading
import time
from typing import Any, Dict, Optional, Tuple, Union

import numpy as np

from ..core.types import CameraIntrinsics
from ..errors import FrameError, RecordingError
from ..net.protocol import wire_time_ns
from .mcap_format import image_message
from .mcap_writer import McapRecorder, encode_image, import_mcap_writer

_log = logging.getLogger(__name__)
PathLike = Union[str, "os.PathLike[str]"]
_STOP = object()


def rotated_path(path: str) -> str:
    """``run.mcap`` → ``run.1.mcap``: where the previous full file goes."""
    root, ext = os.path.splitext(path)
    return f"{root}.1{ext or '.mcap'}"


class BackgroundRecorder:
    """Records frames and readings into ``path`` from a writer thread.

    Parameters
    ----------
    path : str or path-like
        The MCAP file; the previous full one becomes :func:`rotated_path`.
    camera : CameraIntrinsics
        Written as ``/camera/calibration`` at the start of every file.
    max_bytes : int, optional
        Rotate once a file holds this many bytes; ``None``: no bound.
    queue_items : int
        Frames and readings waiting for the writer; beyond that they are dropped.
    """

    def __init__(
        self,
        path: PathLike,
        camera: CameraIntrinsics,
        max_bytes: Optional[int] = None,
        image_format: str = "jpeg",
        jpeg_quality: int = 90,
        queue_items: int = 64,
        logger: Optional[logging.Logger] = None,
    ) -> None:
        import_mcap_writer()  # fail now, in the caller, when the extra is missing
        self.path = os.fspath(path)
        self.camera = camera
        self.max_bytes = max_bytes
        self.image_format = image_format
        self.jpeg_quality = jpeg_quality
        self.counts: Dict[str, int] = {"frames": 0, "readings": 0, "dropped": 0, "rotations": 0,
                                       "errors": 0, "bad_frames": 0}
        self.failed: Optional[str] = None  # why recording stopped, if it did
        self._log = logger or _log
        self._queue: queue.Queue[Any] = queue.Queue(queue_items)
        # The first file is opened here so that a bad path fails in the caller.
        self._recorder: Optional[McapRecorder] = self._open(time.time_ns())
        self._abandoned = False
        self._thread = threading.Thread(target=self._run, name="mcap-writer", daemon=True)
        self._thread.start()

    # --- the capture loop's side: never blocks, never raises ---------------

    def add(self, image: np.ndarray, index: int, payload: bytes, t_s: float) -> None:
        """Queue a frame and the reading sent for it, both stamped with the reading's ``t`` (to the µs)."""
        t_ns = wire_time_ns(t_s)
        self.add_frame(image, t_ns, index)
        self.add_reading(payload, t_ns)

    def add_frame(self, image: np.ndarray, t_ns: int, index: int) -> None:
        """Queue one frame (the array is not copied: sources hand out a fresh one per frame)."""
        self._offer(("frame", image, int(t_ns), int(index)))

    def add_reading(self, payload: bytes, t_ns: int) -> None:
        """Queue one published reading."""
        self._offer(("reading", bytes(payload), int(t_ns), 0))

    def _offer(self, item: Tuple[str, Any, int, int]) -> None:
        if self.failed is not None:
            return
        try:
            self._queue.put_nowait(item)
        except queue.Full:
            self.counts["dropped"] += 1

    # --- the writer thread ---------------------------------------------------

    def _open(self, t_ns: int) -> McapRecorder:
        rec = McapRecorder(self.path, image_format=self.image_format, jpeg_quality=self.jpeg_quality)
        rec.write_calibration(self.camera, t_ns)
        return rec

    def _run(self) -> None:
        while True:
            item = self._queue.get()
            if item is _STOP:
                break
            if self.failed is not None:
                continue
            try:
                self._write(item)
            except Exception as exc:  # deliberately broad: a writer that dies leaves close() and the queue stuck
                self._fail(exc)
        self._finish()

    def _write(self, item: Tuple[str, Any, int, int]) -> None:
        kind, data, t_ns, index = item
        if kind == "frame":
            try:
                data = image_message(encode_image(data, self.image_format, self.jpeg_quality),
                                     self.image_format, t_ns)
            except FrameError:
                self.counts["bad_frames"] += 1
                return
        if self._recorder is None:
            self._recorder = self._open(t_ns)
        if kind == "frame":
            self._recorder.write_encoded_image(data, t_ns, index)
            self.counts["frames"] += 1
        else:
            self._recorder.write_reading(data, t_ns)
            self.counts["readings"] += 1
        if self.max_bytes is not None and self._recorder.size_bytes >= self.max_bytes:
            self._rotate()

    def _rotate(self) -> None:
        rec, self._recorder = self._recorder, None
        if rec is not None:
            rec.close()
            os.replace(self.path, rotated_path(self.path))
            self.counts["rotations"] += 1

    def _fail(self, exc: BaseException) -> None:
        self.counts["errors"] += 1
        self.failed = str(exc)
        self._log.warning("recording to %s stopped: %s (the daemon goes on)", self.path, exc)
        rec, self._recorder = self._recorder, None
        if rec is not None:
            with contextlib.suppress(RecordingError, OSError):
                rec.close()

    def _finish(self) -> None:
        rec, self._recorder = self._recorder, None
        if rec is not None:
            try:
                rec.close()
            except (RecordingError, OSError) as exc:
                self._fail(exc)

    def close(self, timeout_s: float = 10.0) -> None:
        """Write what is queued, finish the file and stop the thread, within ``timeout_s``. Safe to call twice.

        A writer stuck in a write (a USB stick pulled, an NFS server gone) never
        holds the caller (a daemon asked to stop) past ``timeout_s``: the file is
        then left unfinished (a reader reads it up to its last complete chunk).
        """
        deadline = time.monotonic() + timeout_s
        if self._thread.is_alive() and not self._abandoned:
            with contextlib.suppress(queue.Full):
                self._queue.put(_STOP, timeout=timeout_s)  # waits only while the queue is full
            self._thread.join(max(0.0, deadline - time.monotonic()))
        if self._thread.is_alive() and not self._abandoned:
            self._abandoned = True  # a second close() does not wait again
            self._log.warning("recording to %s not finished within %g s: left as it is (the writer is stuck)",
                              self.path, timeout_s)

    def __enter__(self) -> BackgroundRecorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
