"""How ``rangebearing run``'s own process runs: its garbage collected after the send, its wake-ups on time.

Both are process-wide policies, so only the daemon's own process takes them (``Daemon(freeze_gc=True)``,
as ``run`` builds it); a library must not set them on import.

* **The collector after the send.** CPython's cyclic collector runs whenever 700 more container
  objects were made than freed, wherever the loop is: here once every ~35 frames at 90 fps, a
  28-300 µs pause, i.e. in ~3 % of the frames, inside their capture → send time (docs/daemon-cost.md).
  After the first frame every object alive is frozen out of it (start-up's modules and tables are
  never garbage) and the automatic threshold is raised tenfold as a safety net (threads of the view
  page or a recorder allocate too); the loop itself collects, with CPython's own thresholds and
  generation rule, once its datagram is out (:meth:`Collector.frame_sent`). Same work, out of the path.
* **Wake-ups on time.** A paced source sleeps until its next frame is due; Linux lets a sleeping
  thread wake up to its *timer slack* late (50 µs by default) to batch timers. That lateness is in
  every frame's capture → send time; the daemon's threads ask for 1 µs (``PR_SET_TIMERSLACK``,
  inherited by the threads it starts). A camera's frames wake the reader by an event, not a timer.
"""

from __future__ import annotations

import ctypes
import gc
import sys

THRESHOLDS = (700, 10, 10)  # CPython's own: the loop collects on these
SAFETY_FACTOR = 10  # the automatic collector's young threshold, times the loop's: only if the loop falls behind
PR_SET_TIMERSLACK = 29  # linux/prctl.h
TIMER_SLACK_NS = 1000


def precise_wakeups(slack_ns: int = TIMER_SLACK_NS) -> bool:
    """Set the calling thread's timer slack (and that of the threads it starts) to ``slack_ns``.

    Returns whether the kernel took it (False off Linux or without ``prctl``).
    """
    if not sys.platform.startswith("linux"):
        return False
    try:  # the C library the process already runs on (no ctypes.util.find_library: it runs ldconfig)
        prctl = ctypes.CDLL(None).prctl
    except (OSError, AttributeError):
        return False
    prctl.argtypes = [ctypes.c_int, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_ulong]
    prctl.restype = ctypes.c_int
    return prctl(PR_SET_TIMERSLACK, slack_ns, 0, 0, 0) == 0


class Collector:
    """The loop's garbage collection: start-up frozen out after the first frame, then collected after each send.

    Parameters
    ----------
    thresholds : tuple of int
        Young objects before a collection, then collections of each generation before
        the next one up (CPython's rule, :func:`gc.set_threshold`).
    """

    def __init__(self, thresholds: tuple = THRESHOLDS) -> None:
        self.thresholds = thresholds
        self.collections = [0, 0, 0]  # run by the loop, per generation

    def frame_sent(self, first: bool) -> None:
        """Call once a frame's datagram is out (``first``: the daemon's first frame)."""
        if first:
            gc.freeze()
            t0, t1, t2 = self.thresholds
            gc.set_threshold(t0 * SAFETY_FACTOR, t1, t2)
            gc.enable()  # `run` keeps the collector off while starting (cli.main)
            return
        c0, c1, c2 = gc.get_count()
        t0, t1, t2 = self.thresholds
        if c0 <= t0:
            return
        # the oldest generation over its count, as CPython picks it (collecting one counts in the next up);
        # CPython's guard on full collections of a large heap is moot here, start-up's objects are frozen
        gen = 2 if c2 > t2 else 1 if c1 > t1 else 0
        gc.collect(gen)
        self.collections[gen] += 1
