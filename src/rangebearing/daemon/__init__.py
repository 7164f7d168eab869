"""The daemon behind ``rangebearing run``: the capture loop, its housekeeping, its figures, systemd."""

from __future__ import annotations

from .loop import Daemon

__all__ = ["Daemon"]
