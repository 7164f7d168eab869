"""The capture loop behind ``rangebearing run``: frames in, UDP readings out, systemd told.

Short wiring over the library: a :class:`~rangebearing.sources.base.FrameSource`,
a :class:`~rangebearing.core.pipeline.Pipeline` and a
:class:`~rangebearing.net.publisher.Publisher`, all passed in. The loop always
takes the source's newest frame (the source counts what it skipped), skips and
counts bad frames, never lets a network fault through, and on SIGHUP swaps in a
freshly validated config between frames.
"""

from __future__ import annotations

import dataclasses
import logging
import signal
import threading
import time
from typing import Callable, Optional

from ..config import Config, SourceConfig, load_config
from ..core.pipeline import Pipeline
from ..errors import ConfigError, FrameError, ProtocolError, RangeBearingError, SourceError
from ..net.protocol import encode_reading
from ..net.publisher import Publisher
from ..sources.base import FrameSource
from .sdnotify import Notifier
from .stats import LoopStats, Summary

log = logging.getLogger("rangebearing.daemon.loop")

SourceFactory = Callable[[Config, Callable[[float], object]], FrameSource]
PublisherFactory = Callable[[Config], Publisher]
Echo = Callable[[bytes], None]


class Daemon:
    """Run the capture loop until the source ends, a stop is requested, or the source fails.

    Parameters
    ----------
    cfg : Config
        The validated start-up configuration.
    open_source : callable
        ``(cfg, sleep) -> FrameSource`` (opened); ``sleep`` is interruptible by a stop.
    open_publisher : callable
        ``cfg -> Publisher``.
    notifier : Notifier
        systemd notifications (does nothing outside systemd).
    config_path : str, optional
        File re-read on SIGHUP.
    echo : callable, optional
        Called with every datagram sent (``--echo`` prints it).
    source_override : SourceConfig, optional
        The source given on the command line; kept over the file's on reload.
    """

    def __init__(
        self,
        cfg: Config,
        open_source: SourceFactory,
        open_publisher: PublisherFactory,
        notifier: Notifier,
        config_path: Optional[str] = None,
        echo: Optional[Echo] = None,
        source_override: Optional[SourceConfig] = None,
    ) -> None:
        self.cfg = cfg
        self._open_source = open_source
        self._open_publisher = open_publisher
        self.notifier = notifier
        self.config_path = config_path
        self.echo = echo
        self.source_override = source_override
        self.stats = LoopStats()
        self._stop = threading.Event()
        self._reload = threading.Event()
        self._source: Optional[FrameSource] = None
        self._pipe = Pipeline(cfg.pipeline)
        self._publisher: Optional[Publisher] = None
        self._ready = False  # READY=1 sent: the first frame went through
        self._dropped_before = 0  # drops of sources closed by a reload

    # --- control, safe to call from signal handlers ---------------------------------
    def stop(self) -> None:
        self._stop.set()

    def request_reload(self) -> None:
        self._reload.set()

    def install_signal_handlers(self) -> None:
        signal.signal(signal.SIGTERM, lambda *_: self.stop())
        signal.signal(signal.SIGINT, lambda *_: self.stop())
        signal.signal(signal.SIGHUP, lambda *_: self.request_reload())

    @property
    def dropped(self) -> int:
        return self._dropped_before + (self._source.dropped if self._source else 0)

    def summary(self) -> Summary:
        return self.stats.summary(self.dropped)

    # --- the loop ---------------------------------------------------------------------
    def run(self) -> int:
        """Returns 0 when the source ends or a stop was requested, 1 when the source failed."""
        self._pipe = Pipeline(self.cfg.pipeline)
        self._publisher = self._open_publisher(self.cfg)
        try:
            self._source = self._open_source(self.cfg, self._stop.wait)
            return self._loop()
        except SourceError as exc:
            log.error("frame source failed: %s", exc)
            return 1
        finally:
            self.notifier.stopping()
            if self._source is not None:
                self._source.close()
            self._publisher.close()
            log.info("stopped: %s", self.summary().line())

    def _loop(self) -> int:
        clock = time.monotonic_ns
        wd = self.notifier.watchdog_interval_s()
        wd_every_ns = int(wd * 1e9 / 2) if wd else 0
        last_wd = last_status = clock()
        seq = 0
        source, pipe, publisher = self._source, self._pipe, self._publisher
        while not self._stop.is_set():
            if self._reload.is_set():
                self._reload.clear()
                self._do_reload()
                source, pipe, publisher = self._source, self._pipe, self._publisher
            t_read = clock()
            try:
                frame = source.read()
                if frame is None:
                    log.info("end of stream")
                    return 0
                t0 = clock()
                result = pipe.process(frame.image)
            except FrameError as exc:
                self._bad_frame("bad frame skipped", exc)
                continue
            t1 = clock()
            t_unix = time.time() - (t1 - frame.t_mono_ns) / 1e9
            try:
                payload = encode_reading(
                    self.cfg.publish.robot_id, seq, t_unix, result.landmarks, self.stats.fps, self.dropped
                )
            except ProtocolError as exc:  # e.g. a NaN reading: skip the frame, keep going
                self._bad_frame("reading not encodable, frame skipped", exc)
                continue
            publisher.send(payload)
            t2 = clock()
            seq += 1
            self.stats.frame_done(
                t2,
                t2 - frame.t_mono_ns,
                len(result.landmarks),
                {"wait": t0 - t_read, "process": t1 - t0, "send": t2 - t1},
            )
            if self.echo:
                self._echo(payload)
            if not self._ready:
                self.notifier.ready()
                self._ready = True
                log.info("ready: first frame processed (%d×%d)", frame.image.shape[1], frame.image.shape[0])
            if wd_every_ns and t2 - last_wd >= wd_every_ns:
                self.notifier.watchdog()  # only while frames flow: a stuck camera ends in a restart
                last_wd = t2
            if t2 - last_status >= self.cfg.daemon.status_interval_s * 1e9:
                s = self.summary()
                log.info("%s", s.line())
                self.notifier.status(f"{s.fps:.1f} fps, {s.landmarks} landmarks in view, {s.dropped} dropped")
                last_status = t2
        return 0

    def _echo(self, payload: bytes) -> None:
        """Show a sent reading; a closed terminal or pipe stops the echo, not the daemon."""
        try:
            self.echo(payload)  # type: ignore[misc]
        except (OSError, RangeBearingError) as exc:
            log.warning("echo stopped: %s", exc)
            self.echo = None

    def _bad_frame(self, what: str, exc: Exception) -> None:
        """Count a skipped frame; log the first three, then every hundredth (no flooding the journal)."""
        self.stats.bad_frames += 1
        n = self.stats.bad_frames
        if n <= 3 or n % 100 == 0:
            log.warning("%s (%d so far): %s", what, n, exc)

    def _do_reload(self) -> None:
        """Re-read the config file and swap it in; keep everything as it was if the new one is bad."""
        self.notifier.reloading()
        try:
            if not self.config_path:
                log.warning("SIGHUP ignored: no --config file to reload")
                return
            try:
                new = load_config(self.config_path)
                if self.source_override is not None:  # a source given on the command line wins
                    new = dataclasses.replace(new, source=self.source_override)
                new_pub = self._open_publisher(new)
            except ConfigError as exc:
                log.error("reload rejected, keeping the running config: %s", exc)
                return
            if new.source != self.cfg.source and not self._swap_source(new):
                new_pub.close()
                return
            self._publisher.close()
            self._publisher, self._pipe, self.cfg = new_pub, Pipeline(new.pipeline), new
            log.info("config reloaded from %s", self.config_path)
        finally:
            if self._ready:
                self.notifier.ready()

    def _swap_source(self, new: Config) -> bool:
        """Close the running source and open the new config's; on failure reopen the old one and say False.

        The old source is closed first: a camera cannot be opened twice. If the
        old one cannot be reopened either, SourceError ends the run (and systemd
        restarts the service).
        """
        log.info("camera settings changed: reopening the frame source")
        old = self._source
        self._source = None
        if old is not None:
            self._dropped_before += old.dropped
            old.close()
        try:
            self._source = self._open_source(new, self._stop.wait)
            return True
        except SourceError as exc:
            log.error("reload rejected: cannot open the new frame source (%s); reopening the old one", exc)
            self._source = self._open_source(self.cfg, self._stop.wait)
            return False
