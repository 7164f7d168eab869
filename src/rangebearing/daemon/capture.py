"""Camera faults ridden out: the daemon's capture policy, one place, tested through the fake camera.

* A capture error (``CameraError`` from ``capture_request``) is retried in
  process with back-off (50 ms doubling to 1 s); a timeout or a bad frame is a
  skipped frame (``FrameError``, counted by the loop).
* No frame for half the capture budget (``source.timeout_s × source.retries``,
  8 s by default, at most 12): the camera is closed and reopened, once per stall.
* No frame for the whole budget: :class:`CameraGone`, and the daemon exits 1
  cleanly, well before the unit's ``WatchdogSec=20s`` would SIGABRT it;
  systemd restarts it (``systemd/rangebearing.service`` says why the limits are
  what they are). WATCHDOG=1 is only ever sent after a frame, so it stays honest.
* At start the camera may be missing or busy (a robot that boots before its
  camera): opening is retried for ``source.open_timeout_s`` (before READY=1
  systemd's watchdog is not armed), then the same clean exit.
* Every camera capture runs in a reader thread, so a call wedged inside the camera
  stack never holds the loop (a source whose ``may_block`` is False, recorded
  and synthetic frames that only wait on the stop event, is read in the loop's
  own thread, saving the hand-off): past ``timeout_s`` + 1 s it counts as a failed
  capture, SIGTERM still ends the run promptly, and :attr:`CaptureGuard.wedged`
  tells the caller to leave with ``os._exit`` rather than wait for the thread.
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Callable, Optional, Union

from ..errors import CameraError, CameraLibraryError, FrameError, SourceError
from ..sources.base import Frame, FrameSource

log = logging.getLogger("rangebearing.daemon")

Opener = Callable[[Callable[[float], object]], FrameSource]  # sleep -> an opened source
GRACE_S = 1.0  # beyond its own timeout, how long a capture call may take before it counts as wedged
PAUSE_SLICE_S = 0.1  # the longest a paced source sleeps before it looks at the stop flag again


class CameraGone(CameraError):
    """No frame for the whole capture budget (or no camera within the start budget)."""


class SourceUnusable(SourceError):
    """A source that waiting cannot mend (a recording that is missing, empty or not a video): never retried."""


class _Reader:
    """One source's reads, run in a thread of their own (unless the source says its reads cannot wedge)."""

    def __init__(self, source: FrameSource) -> None:
        self.source = source
        self._request = threading.Event()
        self.done = threading.Event()
        self.result: Union[Frame, BaseException, None] = None
        self.busy = False
        self._closing = False
        # recorded and synthetic frames wait only on the stop event: read them in the loop's thread (no hand-off)
        self.threaded = bool(getattr(source, "may_block", True))
        if self.threaded:
            threading.Thread(target=self._run, name="capture", daemon=True).start()

    def _run(self) -> None:
        while True:
            self._request.wait()
            self._request.clear()
            if self._closing:
                return
            try:
                self.result = self.source.read()
            except BaseException as exc:  # handed to the loop's thread, which decides
                self.result = exc
            self.busy = False
            self.done.set()

    def start(self) -> None:
        self.busy = True
        self.done.clear()
        self._request.set()

    def stop(self) -> None:
        self._closing = True
        self._request.set()


class CaptureGuard:
    """Reads frames through the policy above; :meth:`read` is what the loop calls.

    Parameters
    ----------
    opener : callable
        ``sleep -> FrameSource``, opened; ``sleep`` returns True to stop a source's own retries.
    stop : threading.Event
        Set when the daemon is asked to stop (every wait here ends on it).
    timeout_s, budget_s, start_budget_s : float
        One capture's wait; seconds without a frame before giving up; seconds to open at start.
    """

    def __init__(self, opener: Opener, stop: threading.Event, timeout_s: float, budget_s: float,
                 start_budget_s: float, clock: Callable[[], float] = time.monotonic) -> None:
        self._opener = opener
        self._stop = stop
        self.timeout_s, self.budget_s, self.start_budget_s = timeout_s, budget_s, start_budget_s
        self._clock = clock
        self._reader: Optional[_Reader] = None
        self._last_frame = clock()
        self._reopened = False
        self._fresh = False  # the last read returned a frame
        self._backoff_s = 0.0
        self.faults = 0
        self.reopens = 0
        self.wedged = False  # a capture call never returned: leave the process with os._exit
        self.dropped_before = 0

    @property
    def source(self) -> Optional[FrameSource]:
        return None if self._reader is None else self._reader.source

    def _pause(self, s: float) -> bool:
        """A paced source's wait for its next frame; True once a stop is requested.

        ``time.sleep`` costs half the CPU of ``Event.wait`` (~50 against ~100 µs a
        wait here: one system call, no condition variable), once a frame. It is
        cut into slices of at most :data:`PAUSE_SLICE_S` and the stop flag read
        after each, so a stop from another thread ends it within a slice (a
        signal's handler runs at once and the pacer sees the flag); the pacer
        sleeps again until its frame is due.
        """
        if self._stop.is_set():
            return True
        time.sleep(min(max(s, 0.0), PAUSE_SLICE_S))
        return self._stop.is_set()

    def interrupt(self) -> None:
        """Wake a wait for a capture (called with the stop request, from a signal handler)."""
        reader = self._reader  # read once: the loop's thread may close it (None) meanwhile (a source swap)
        if reader is not None:
            reader.done.set()

    # --- opening ----------------------------------------------------------------------
    def open(self, opener: Optional[Opener] = None, budget_s: Optional[float] = None) -> bool:
        """Open (``opener`` or the current one) within ``budget_s``; False if a stop came first.

        Raises CameraGone when the budget passes without an open camera.
        """
        opener = opener or self._opener
        budget = self.start_budget_s if budget_s is None else budget_s
        deadline = self._clock() + budget
        delay = 0.5
        opening = True

        def sleep(s: float) -> bool:
            """Ends on a stop; while opening, also at the start budget's end. Sources pace their frames with it."""
            if not opening:
                return self._pause(s)
            return self._stop.wait(min(s, max(0.0, deadline - self._clock()))) or self._clock() >= deadline

        while not self._stop.is_set():
            try:
                source = opener(sleep)
            except SourceUnusable:
                raise
            except SourceError as exc:
                left = deadline - self._clock()
                if isinstance(exc, CameraLibraryError):  # not installed: no retry brings it
                    raise
                if left <= 0:
                    raise CameraGone(f"{exc}; no usable camera within {budget:g} s") from None
                log.warning("%s; retrying in %.1f s (%.0f s left)", exc, min(delay, left), left)
                self._stop.wait(min(delay, left))
                delay = min(delay * 2.0, 2.0)
                continue
            opening = False  # the budget was for opening: frames are paced with plain, stoppable sleeps
            self._reader = _Reader(source)
            self._last_frame = self._clock()
            self._opener = opener
            return True
        return False

    def swap(self, opener: Opener, budget_s: float, old: Opener, old_budget_s: float) -> bool:
        """Close the running source and open ``opener``'s; on failure reopen ``old`` and say False.

        The old source is closed first: a camera cannot be opened twice. If the
        old one cannot be reopened either, CameraGone ends the run (and systemd
        restarts the service).
        """
        log.info("camera settings changed: reopening the frame source")
        self.close()
        try:
            if self.open(opener, budget_s=budget_s):
                return True
        except (CameraGone, SourceUnusable, CameraLibraryError) as exc:  # a reload never ends the daemon
            log.error("reload rejected: cannot open the new frame source (%s); reopening the old one", exc)
        self.open(old, budget_s=old_budget_s)
        return False

    def close(self) -> None:
        reader, self._reader = self._reader, None
        if reader is None:
            return
        self.dropped_before += reader.source.dropped
        if reader.busy:  # wedged in a capture call: its thread is left behind
            self.wedged = True
        reader.stop()
        reader.source.close()

    # --- reading ----------------------------------------------------------------------
    def read(self) -> Optional[Frame]:
        """The next frame; ``None`` at the end of a recording or when a stop was requested.

        Raises FrameError for a skipped frame (timeout, bad frame) and CameraGone
        when the capture budget is spent.
        """
        if self._fresh:  # the budget counts time spent waiting for the camera, not processing frames
            self._last_frame, self._fresh = self._clock(), False
        while not self._stop.is_set():
            self._spend_budget()
            if self._reader is None:
                continue
            try:
                frame = self._read_once(self._reader)
            except FrameError:
                raise
            except SourceError as exc:  # a capture that failed: retry with back-off
                self.faults += 1
                self._backoff_s = min(max(self._backoff_s * 2.0, 0.05), 1.0)
                if self.faults <= 3 or self.faults % 100 == 0:
                    log.warning("capture failed (%d so far), retrying in %.2f s: %s", self.faults, self._backoff_s, exc)
                self._stop.wait(self._backoff_s)
                continue
            if frame is not None:
                self._last_frame, self._reopened, self._backoff_s, self._fresh = self._clock(), False, 0.0, True
            return frame
        return None

    def _read_once(self, reader: _Reader) -> Optional[Frame]:
        if not reader.threaded:
            return reader.source.read()
        if not reader.busy:
            reader.start()
        if not reader.done.wait(self.timeout_s + GRACE_S) or reader.busy:
            if self._stop.is_set():
                return None
            raise FrameError(f"capture call did not return within {self.timeout_s + GRACE_S:g} s")
        result = reader.result
        if isinstance(result, BaseException):
            raise result
        return result

    def _spend_budget(self) -> None:
        idle = self._clock() - self._last_frame
        if idle >= self.budget_s:
            raise CameraGone(f"no frame for {idle:.1f} s (the capture budget, source.timeout_s × source.retries, "
                             f"is {self.budget_s:g} s); exiting for the service manager to restart the camera")
        if self._reader is None or (idle >= self.budget_s / 2 and not self._reopened):
            if self._reader is not None:
                log.warning("no frame for %.1f s: closing and reopening the camera", idle)
                self._reopened = True
                self.reopens += 1
                self.close()
            last = self._last_frame
            self.open(budget_s=max(0.0, self.budget_s - idle))
            self._last_frame = last  # reopening does not reset the budget: only a frame does
