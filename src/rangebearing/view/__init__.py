"""``rangebearing view``: a live web page of what the robot sees, served by the robot.

:class:`ViewHub` takes frames from the capture loop (only while a browser
watches, at a capped rate) and encodes them on its own thread;
:class:`ViewServer` serves the page, the MJPEG streams and the JSON state with
the standard library's ``ThreadingHTTPServer``. See ``docs/view.md``.
"""

from __future__ import annotations

import importlib
from typing import Any

# Loaded on first use: the daemon imports view.thresholds on every start, and must not pay for the
# HTTP server (http.server, email, …) unless daemon.view_port asks for it.
_LAZY = {"Snapshot": ".hub", "ViewHub": ".hub", "ViewServer": ".server", "Thresholds": ".thresholds"}

__all__ = ["Snapshot", "Thresholds", "ViewHub", "ViewServer"]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
