"""What the capture loop owes systemd and the journal, kept out of the loop itself.

READY=1 once the first frame went through (so ``systemctl start`` waits for a
working camera), WATCHDOG=1 only while frames flow (a stuck camera ends in a
watchdog restart rather than a silent robot), and every ``status_interval_s``
a STATUS= line and a log line with the loop's figures.
"""

from __future__ import annotations

import logging
from typing import Callable, Optional, Protocol

from .stats import Summary

log = logging.getLogger("rangebearing.daemon")


class ServiceManager(Protocol):
    """The part of :class:`~rangebearing.daemon.sdnotify.Notifier` the daemon uses."""

    def ready(self, status: Optional[str] = None) -> bool: ...
    def watchdog(self) -> bool: ...
    def status(self, text: str) -> bool: ...
    def stopping(self) -> bool: ...
    def reloading(self) -> bool: ...
    def watchdog_interval_s(self) -> Optional[float]: ...


class Housekeeping:
    """READY, WATCHDOG and STATUS at the right moments; call :meth:`frame_done` after every frame sent.

    Parameters
    ----------
    notifier : ServiceManager
        systemd notifications (a no-op outside systemd).
    summary : callable
        Returns the loop's current figures.
    status_interval_s : float
        Seconds between STATUS= and log lines.
    """

    def __init__(self, notifier: ServiceManager, summary: Callable[[], Summary], status_interval_s: float) -> None:
        self.notifier = notifier
        self._summary = summary
        self.status_interval_ns = int(status_interval_s * 1e9)
        wd = notifier.watchdog_interval_s()
        # ping at most 1 s after a frame: a stall is then noticed WatchdogSec after its last frame, not
        # up to half a period earlier, so the daemon's own capture budget always ends it first
        self._wd_every_ns = int(min(wd / 2, 1.0) * 1e9) if wd else 0
        self.ready = False
        self._last_wd_ns: Optional[int] = None
        self._last_status_ns: Optional[int] = None

    def frame_done(self, now_ns: int, width_px: int, height_px: int) -> None:
        """A frame's reading went out at ``now_ns`` (monotonic)."""
        if not self.ready:
            self.notifier.ready()
            self.ready = True
            log.info("ready: first frame processed (%d×%d)", width_px, height_px)
            self._last_wd_ns = self._last_status_ns = now_ns
        if self._wd_every_ns and now_ns - (self._last_wd_ns or 0) >= self._wd_every_ns:
            self.notifier.watchdog()
            self._last_wd_ns = now_ns
        if now_ns - (self._last_status_ns or 0) >= self.status_interval_ns:
            s = self._summary()
            log.info("%s", s.line())
            self.notifier.status(f"{s.fps:.1f} fps, {s.landmarks} landmarks in view, {s.dropped} dropped")
            self._last_status_ns = now_ns

    def reloading(self) -> None:
        self.notifier.reloading()

    def reloaded(self) -> None:
        """The reload is over (applied or rejected): READY=1 again if the service was ready."""
        if self.ready:
            self.notifier.ready()

    def stopping(self) -> None:
        self.notifier.stopping()
