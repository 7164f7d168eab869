"""SIGHUP's config reload for the capture loop: swap in a validated config between frames, never die of it."""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

from ..config import Config
from ..core.pipeline import Pipeline
from ..errors import ConfigError, SourceError

if TYPE_CHECKING:
    from .capture import CaptureGuard
    from .housekeeping import Housekeeping

log = logging.getLogger("rangebearing.daemon")


class Reloading:
    """The reload half of :class:`~rangebearing.daemon.loop.Daemon` (it provides the attributes used here)."""

    cfg: Config
    guard: CaptureGuard
    house: Housekeeping
    _pipe: Pipeline
    _publisher: Any
    _reload: Any
    _reload_config: Any
    _open_source: Any
    _open_publisher: Any
    view: Any

    def _do_reload(self) -> None:
        """Swap in the reloaded config; keep everything as it was if the new one is bad.

        Nothing a config file holds may end a running daemon: beyond ConfigError, any
        failure of the reload itself is logged and the running config kept.
        """
        try:
            self._reload_once()
        except SourceError:
            raise  # the old camera could not be reopened either: the camera policy decides
        except Exception as exc:  # deliberately broad: a reload must never end the daemon
            log.error("reload failed, keeping the running config: %s: %s", type(exc).__name__, str(exc)[:300])

    def _reload_once(self) -> None:
        self._reload.clear()
        self.house.reloading()
        try:
            if self._reload_config is None:
                log.warning("SIGHUP ignored: no --config file to reload")
                return
            try:
                new = self._reload_config()
                new_pub = self._open_publisher(new)
            except ConfigError as exc:
                log.error("reload rejected, keeping the running config: %s", exc)
                return
            if new.source != self.cfg.source and not self._swap_source(new):
                new_pub.close()
                return
            self._publisher.close()  # type: ignore[union-attr]
            if new.pipeline != self.cfg.pipeline:
                self._pipe = Pipeline(new.pipeline, first_track_id=self._pipe.next_track_id)  # ids never reused
            if new.daemon.view_port != self.cfg.daemon.view_port or new.daemon.view_host != self.cfg.daemon.view_host:
                log.warning("daemon.view_port / view_host changes take effect at the next start")
            self._publisher, self.cfg = new_pub, new
            src = new.source
            self.guard.timeout_s, self.guard.budget_s = src.timeout_s, src.timeout_s * src.retries
            if self.view is not None:
                from ..view.thresholds import Thresholds  # with the view page only
                self.view.reset_thresholds(Thresholds.of(new.detection))
            log.info("config reloaded")
        finally:
            self.house.reloaded()

    def _swap_source(self, new: Config) -> bool:
        """Open the new config's source in place of the running one (:meth:`CaptureGuard.swap`)."""
        old = self.cfg
        return self.guard.swap(lambda sleep: self._open_source(new, sleep), new.source.timeout_s * 2,
                               lambda sleep: self._open_source(old, sleep), old.source.open_timeout_s)
