"""The capture loop behind ``rangebearing run``: frames in, UDP readings out.

Short wiring over the library: a :class:`~rangebearing.sources.base.FrameSource`, a
:class:`~rangebearing.core.pipeline.Pipeline` and a :class:`~rangebearing.net.publisher.Publisher`, all passed
in; systemd's READY/WATCHDOG/STATUS live in :mod:`.housekeeping`. The loop always takes the source's newest
frame (the source counts what it skipped), skips and counts bad frames and frames the detector fails on, never
lets a network fault through, and on SIGHUP swaps in the config that the injected ``reload`` returns, between
frames; a reload can never end the daemon. Camera faults are ridden out by :mod:`.capture`.

Exit status: 0 for the end of a recording or a requested stop (SIGTERM at any moment, camera back-off
included), 1 when the camera is gone past its budget, 2 when the first frame cannot fit the configuration (another
aspect ratio; a frame of another size after good ones is skipped and counted).
"""

from __future__ import annotations

import dataclasses
import logging
import signal
import threading
import time
from typing import TYPE_CHECKING, Callable, Optional, Tuple

from .. import _signals
from ..config import Config
from ..core.guarded import DetectorFault, process_or_skip, scan_later_or_skip
from ..core.pipeline import Pipeline
from ..core.types import FrameResult
from ..errors import FrameError, FrameShapeError, ProtocolError, RangeBearingError, SourceError
from ..net.fit import encode_fitting
from ..net.publisher import Publisher
from ..sources.base import Frame, FrameSource, kept
from .capture import CaptureGuard
from .housekeeping import Housekeeping, ServiceManager
from .process import Collector, precise_wakeups
from .recorder import NoRecorder, Recorder
from .reload import Reloading
from .stats import LoopStats, Summary

if TYPE_CHECKING:
    from ..view.hub import ViewHub

log = logging.getLogger("rangebearing.daemon")

SourceFactory = Callable[[Config, Callable[[float], object]], FrameSource]
PublisherFactory = Callable[[Config], Publisher]
Reload = Callable[[], Config]
Echo = Callable[[bytes], None]


class Daemon(Reloading):
    """Run the capture loop until the source ends, a stop is requested, or the source fails.

    Parameters
    ----------
    cfg : Config
        The validated start-up configuration.
    open_source : callable
        ``(cfg, sleep) -> FrameSource`` (opened); ``sleep`` is interruptible by a stop.
    open_publisher : callable
        ``cfg -> Publisher``.
    notifier : ServiceManager
        systemd notifications (:class:`~rangebearing.daemon.sdnotify.Notifier`; a no-op outside systemd).
    reload : callable, optional
        Called on SIGHUP: returns the new validated config or raises ConfigError
        (the command line decides what a reload means, e.g. that its own
        ``--source`` wins over the file's). ``None``: SIGHUP is logged and ignored.
    echo : callable, optional
        Called with every datagram sent (``--echo`` prints it).
    view : ViewHub, optional
        The live web page (:mod:`rangebearing.view`): offered a frame only while
        a browser watches, at its capped rate; its threshold changes are applied
        between frames.
    recorder : Recorder, optional
        Given every frame with the reading sent for it (``run --record``); closed when the loop ends.
    freeze_gc : bool
        ``rangebearing run``'s own process (:mod:`.process`): after the first frame, ``gc.freeze`` every object
        alive (modules, config, tables: never garbage), then collect after each send, never inside a frame's
        capture → send; and wake-ups without timer slack.
    """

    def __init__(
        self,
        cfg: Config,
        open_source: SourceFactory,
        open_publisher: PublisherFactory,
        notifier: ServiceManager,
        reload: Optional[Reload] = None,
        echo: Optional[Echo] = None,
        view: Optional[ViewHub] = None,
        recorder: Optional[Recorder] = None,
        freeze_gc: bool = False,
    ) -> None:
        self.cfg = cfg
        self._collector = Collector() if freeze_gc else None
        self._open_source = open_source
        self._open_publisher = open_publisher
        self._reload_config = reload
        self.echo = echo
        self.view = view
        self.recorder = recorder or NoRecorder()
        self._recording = recorder is not None
        self.stats = LoopStats()
        self.house = Housekeeping(notifier, self.summary, cfg.daemon.status_interval_s)
        self._stop = threading.Event()
        self._reload = threading.Event()
        self.guard = self._guard(cfg)
        self._pipe = Pipeline(cfg.pipeline)
        self._publisher: Optional[Publisher] = None

    def _guard(self, cfg: Config) -> CaptureGuard:
        src = cfg.source
        return CaptureGuard(lambda sleep: self._open_source(cfg, sleep), self._stop, src.timeout_s,
                            src.timeout_s * src.retries, src.open_timeout_s)

    # --- control, safe to call from signal handlers ---------------------------------
    def stop(self) -> None:
        self._stop.set()
        self.guard.interrupt()

    def request_reload(self) -> None:
        self._reload.set()

    def install_signal_handlers(self) -> None:
        """SIGTERM/SIGINT stop, SIGHUP reloads; signals noted while starting (``_signals``) are honoured."""
        # acted on in a thread of their own: a handler that sets an Event can deadlock the loop (_signals.Relay)
        _signals.handle({signal.SIGTERM: self.stop, signal.SIGINT: self.stop, signal.SIGHUP: self.request_reload})
        early = _signals.taken_over()
        if early["stop"]:
            log.info("SIGTERM arrived while starting: stopping")
            self.stop()
        if early["reload"]:  # the file may have changed after it was read: read it again
            self.request_reload()

    @property
    def dropped(self) -> int:
        source = self.guard.source
        return self.guard.dropped_before + (source.dropped if source else 0)

    def summary(self) -> Summary:
        return self.stats.summary(self.dropped)

    # --- the loop ---------------------------------------------------------------------
    def run(self) -> int:
        """0: the source ended or a stop was requested; 1: the camera is gone; 2: frames the config cannot fit."""
        self._publisher = self._open_publisher(self.cfg)
        if self._collector is not None:
            precise_wakeups()  # a paced frame's sleep ends when it is due, not up to 50 µs later
        try:
            if not self.guard.open():
                return 0  # stopped while the camera was still being waited for
            return self._loop()
        except FrameShapeError as exc:  # every frame would fail the same way: say it once, clearly
            log.error("cannot process these frames: %s", exc)
            self.house.notifier.status(f"failed: {exc}")
            return 2
        except SourceError as exc:
            if self._stop.is_set():  # a requested stop is not a failure, whatever it interrupted
                return 0
            log.error("frame source failed: %s", exc)
            self.house.notifier.status(f"failed: {exc}")
            return 1
        finally:
            self.house.stopping()
            self.guard.close()
            self._publisher.close()
            self.recorder.close()
            log.info("stopped: %s", self.summary().line())

    def _loop(self) -> int:
        clock, thread_cpu, seq = time.monotonic_ns, time.thread_time_ns, 0
        while not self._stop.is_set():
            if self._reload.is_set():
                self._do_reload()
            if self.view is not None:
                self._view_thresholds()
            t_read = clock()
            try:
                frame = self.guard.read()
                if frame is None:
                    if not self._stop.is_set():
                        log.info("end of stream")
                    return 0
                t0, c0 = clock(), thread_cpu()
                result, scan = self._process(frame)
                t1, c1 = clock(), thread_cpu()
                pub = self.cfg.publish
                t_unix = _unix_time(frame, t1)
                payload = encode_fitting(pub.robot_id, seq, t_unix, result.landmarks, self.stats.fps,
                                         self.dropped)  # always one packet: the nearest landmarks if not all fit
            except (FrameError, ProtocolError) as exc:  # a bad frame, or a reading that cannot be encoded
                if isinstance(exc, FrameShapeError) and not self.house.ready:
                    raise  # the first frame already cannot fit: every frame would fail the same way (status 2)
                self._bad_frame(exc)  # after good frames (a recording of mixed sizes): that frame is skipped
                continue
            self._publisher.send(payload)  # type: ignore[union-attr]
            t2, seq = clock(), seq + 1
            stages = {"wait": t0 - t_read, "process": t1 - t0, "send": t2 - t1}
            if scan is not None:  # this frame's full scan, now that its readings are out (counted as its pipeline's)
                c_scan = _scanned(scan)
                c1 += thread_cpu() - c_scan
                stages["scan"] = clock() - t2
            self.stats.frame_done(t2, t2 - frame.t_mono_ns, len(result.landmarks), stages, c1 - c0, result.tracked)
            self._echo(payload)
            if self._recording:
                self.recorder.add(kept(frame), frame.index, payload, t_unix)  # the recorder's thread keeps it
            first = not self.house.ready
            self.house.frame_done(t2, frame.image.shape[1], frame.image.shape[0])
            if self._collector is not None:  # start-up frozen; garbage collected now its datagram is out
                self._collector.frame_sent(first)
            if self.view is not None and self.view.wants(t2):  # only while a browser watches, at its rate
                status = dataclasses.asdict(self.summary())
                self.view.offer(t2, kept(frame), frame.name, result, self.cfg.detection, status)
        return 0

    def _process(self, frame: Frame) -> Tuple[FrameResult, Optional[Callable[[], FrameResult]]]:
        """The frame's readings, and its periodic full scan if ``daemon.scan_after_send`` leaves it for later."""
        if scans_after_send(self.cfg):  # a detector defect is this frame's (or its scan's): core/guarded
            return scan_later_or_skip(self._pipe, frame.image, frame.t_mono_ns / 1e9, frame.lores_yuv420)
        return process_or_skip(self._pipe, frame.image, t_s=frame.t_mono_ns / 1e9, search=frame.lores_yuv420), None

    def _view_thresholds(self) -> None:
        """Detect with the thresholds a browser set, from this frame on (a new pipeline: tracks restart)."""
        new = self.view.take_thresholds()  # type: ignore[union-attr]
        if new is None:
            return
        try:
            cfg = dataclasses.replace(self.cfg, detection=new.apply(self.cfg.detection))
            pipe = Pipeline(cfg.pipeline, first_track_id=self._pipe.next_track_id)  # ids never reused
        except (ValueError, TypeError) as exc:  # validated by the server already; a request never stops the loop
            log.error("thresholds from the view page refused, keeping the running ones: %s", exc)
            from ..view.thresholds import Thresholds  # with the view page only
            self.view.reset_thresholds(Thresholds.of(self.cfg.detection))  # type: ignore[union-attr]
            return
        self.cfg, self._pipe = cfg, pipe
        log.info("thresholds set from the view page: %s (not saved)", new.as_json())

    def _echo(self, payload: bytes) -> None:
        """Show a sent reading; a closed terminal or pipe stops the echo, not the daemon."""
        if self.echo is None:
            return
        try:
            self.echo(payload)
        except (OSError, RangeBearingError) as exc:
            log.warning("echo stopped: %s", exc)
            self.echo = None

    def _bad_frame(self, exc: Exception) -> None:
        """Count a skipped frame; log the first three, then every hundredth (no flooding the journal)."""
        self.stats.bad_frames = n = self.stats.bad_frames + 1
        if n <= 3 or n % 100 == 0:
            what = "reading not encodable, frame skipped" if isinstance(exc, ProtocolError) else "bad frame skipped"
            bug = exc.__cause__ if isinstance(exc, DetectorFault) else None  # a defect's traceback goes to the journal
            log.warning("%s (%d so far): %s", what, n, exc, exc_info=bug)


AUTO_SCAN_AFTER_SEND_FPS = 60.0  # from here a frame period (<= 17 ms) is too short to wait for a full scan


def scans_after_send(cfg: Config) -> bool:
    """``daemon.scan_after_send``, with ``auto`` decided by the frame rate (docs/daemon-cost.md).

    At 90 fps the periodic full scans set the p99 capture-to-send time (CPU
    ~9-10 ms against ~4 ms with the scan after the send); at 30 fps that p99 is a
    quarter of the frame period and the switch's extra tracked step (+3-10 % CPU a
    frame) is what counts, against the 2 % budget.
    """
    v = cfg.daemon.scan_after_send
    return v if isinstance(v, bool) else cfg.source.fps >= AUTO_SCAN_AFTER_SEND_FPS


def _scanned(scan: Callable[[], FrameResult]) -> int:
    """Run a full scan left over from the frame just sent; the thread CPU clock before it (ns).

    A frame that cannot be scanned was read already: the pipeline stays as its tracked step left it.
    """
    c0 = time.thread_time_ns()
    try:
        scan()
    except FrameShapeError:
        raise
    except FrameError as exc:  # a DetectorFault restarted the tracks
        log.warning("full scan after the send failed: %s", exc,
                    exc_info=exc.__cause__ if isinstance(exc, DetectorFault) else None)
    return c0


def _unix_time(frame: Frame, now_mono_ns: int) -> float:
    """The frame's capture time on the wall clock (its monotonic timestamp, moved to ``time.time()``)."""
    return time.time() - (now_mono_ns - frame.t_mono_ns) / 1e9
