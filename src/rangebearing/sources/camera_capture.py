"""One capture from a picamera2, whichever version or stand-in it is: the request, its metadata, a timeout's flush.

Every picamera2 since 0.3.9 takes ``capture_request(wait=t)`` and raises the
futures' TimeoutError past ``t``; an older one (or a stand-in written from the
manual's first examples) takes no ``wait`` at all: the capture is then made
without it, guarded by the daemon's capture thread (``daemon.capture``), and
said once. A false ``wait`` returns the Job (``job.py``): its result is taken.

A timed-out job can still complete: ``process_requests`` pops a job off
``_job_list`` when it executes and signals it only afterwards, outside the
lock, so a job that ran out of time in between is past
``cancel_all_and_flush()`` and its request would sit in the Future, never
released (two such leaks of the 4 buffers stall the camera until it is
reopened). Each capture therefore passes a ``signal_function``
(:class:`LateRequest`) that releases the request of a job given up on; a
picamera2 that takes no ``signal_function`` is captured without it.
A capture that hands back nothing is a skipped frame; metadata that is missing,
not a dict, or fails to read is no metadata (the frame is stamped when it
arrived). Whatever the library raises beyond its timeouts becomes CameraError
(the capture is retried with back-off) or FrameError (the frame is skipped):
never a traceback out of the daemon.
"""

from __future__ import annotations

import concurrent.futures
import logging
import threading
from typing import Any, Callable, Dict, Optional, Tuple

from ..errors import CameraError, FrameError

_log = logging.getLogger(__name__)

TIMEOUTS = (TimeoutError, concurrent.futures.TimeoutError)  # the builtin one is the futures' from Python 3.11


class Notes:
    """Warnings said once per camera (the rest at debug level): a quirk of the library is not news every frame."""

    def __init__(self, camera_num: int) -> None:
        self.camera_num = camera_num
        self._said: set = set()

    def once(self, key: str, msg: str, *args: Any) -> None:
        level = logging.DEBUG if key in self._said else logging.WARNING
        self._said.add(key)
        _log.log(level, "camera %d: " + msg, self.camera_num, *args)


class LateRequest:
    """A capture's ``signal_function``: releases the request of a job that completes after its capture timed out.

    picamera2 calls it with the Job from its event loop once the job is done;
    :meth:`abandon` is called when the capture gave up waiting. Whichever comes
    second releases the request, so it is released exactly once (or never, if
    the capture returned it).
    """

    def __init__(self, notes: Notes) -> None:
        self._notes = notes
        self._lock = threading.Lock()
        self._job: Any = None
        self._abandoned = False

    def __call__(self, job: Any) -> None:
        with self._lock:
            self._job = job
            abandoned = self._abandoned
        if abandoned:
            self._release(job)

    def abandon(self) -> None:
        with self._lock:
            self._abandoned = True
            job = self._job
        if job is not None:
            self._release(job)

    def _release(self, job: Any) -> None:
        try:
            request = job.get_result(0)
            if request is not None and hasattr(request, "release"):
                request.release()
        except Exception as exc:  # deliberately broad: runs in picamera2's event loop, which must not die
            self._notes.once("late", "a request completed after its capture timed out: %r", exc)
            return
        self._notes.once("late", "a request completed after its capture timed out: released")


class Capturer:
    """Makes captures on one open camera; remembers whether it takes ``wait=`` and ``signal_function=``."""

    def __init__(self, notes: Notes, timeout_s: float) -> None:
        self.notes = notes
        self.timeout_s = timeout_s
        self.takes_wait = True
        self.takes_signal = True

    def call(self, capture: Callable[..., Any]) -> Any:
        """``capture(wait=timeout_s)``, or ``capture()`` for a picamera2 that takes no ``wait``."""
        if self.takes_wait:
            try:
                return capture(wait=self.timeout_s)
            except TypeError as exc:  # "unexpected keyword argument 'wait'", "takes 1 positional argument"
                if "argument" not in str(exc):
                    raise CameraError(f"camera {self.notes.camera_num}: capture failed: {exc}") from exc
                self.takes_wait = False
                self.notes.once("wait", "the capture takes no wait= (%s): capturing without a timeout "
                                "(the capture thread still gives up after source.timeout_s)", exc)
        return capture()

    def request(self, capture: Callable[..., Any]) -> Any:
        """A completed request from ``capture_request``; FrameError if the library handed back nothing.

        A timeout (the futures' TimeoutError) is raised on, after the job is marked given up on
        (:class:`LateRequest`): the caller still cancels it with ``cancel_all_and_flush()``.
        """
        late = LateRequest(self.notes)

        def signalled(**wait: Any) -> Any:
            if self.takes_signal:
                try:
                    return capture(signal_function=late, **wait)
                except TypeError as exc:  # "unexpected keyword argument 'signal_function'", "takes 1 positional"
                    if "argument" not in str(exc):
                        raise
                    self.takes_signal = False
                    self.notes.once("signal", "the capture takes no signal_function= (%s): a request completing "
                                    "after a timeout cannot be released", exc)
            return capture(**wait)

        try:
            got = self.call(signalled)
            if got is not None and not hasattr(got, "release") and hasattr(got, "get_result"):
                got = got.get_result(self.timeout_s)  # a Job: this picamera2 took the wait as false
        except TIMEOUTS:
            late.abandon()
            raise
        if got is None:
            raise FrameError(f"camera {self.notes.camera_num}: the capture returned no request")
        return got

    def flush(self, cam: Any) -> None:
        """After a timeout: cancel the job still queued (it would eat the next frame), if the library can."""
        flush = getattr(cam, "cancel_all_and_flush", None)
        if flush is None:
            return
        try:
            flush()
        except Exception as exc:  # deliberately broad: a failed flush costs at most one frame
            self.notes.once("flush", "cancel_all_and_flush() failed after a timeout: %s", exc)

    def metadata(self, request: Any) -> Dict[str, Any]:
        """The request's metadata dict, or {} if it has none that can be read."""
        get = getattr(request, "get_metadata", None)
        if get is None:
            return {}
        try:
            meta = get()
        except Exception as exc:  # deliberately broad: metadata only refines the time stamp
            self.notes.once("metadata", "get_metadata() failed (%s): frames stamped on arrival", exc)
            return {}
        if not isinstance(meta, dict):
            if meta is not None:
                self.notes.once("metadata-type", "get_metadata() gave %s, not a dict: frames stamped on arrival",
                                type(meta).__name__)
            return {}
        return meta


def sensor_fields(metadata: Dict[str, Any]) -> Tuple[Optional[int], Optional[float]]:
    """``SensorTimestamp`` (ns, int) and ``FrameDuration`` (µs), each None where missing or not a number."""
    try:
        sensor_ns: Optional[int] = int(metadata["SensorTimestamp"])
    except (KeyError, TypeError, ValueError, OverflowError):
        sensor_ns = None
    try:
        duration_us: Optional[float] = float(metadata["FrameDuration"])
    except (KeyError, TypeError, ValueError):
        duration_us = None
    if duration_us is not None and not 0.0 < duration_us < 1e9:  # NaN, 0, negative, absurd: not a period
        duration_us = None
    return sensor_ns, duration_us
