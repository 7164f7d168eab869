"""``rangebearing view``: a live web page of what the robot sees, served by the robot.

:class:`ViewHub` takes frames from the capture loop (only while a browser
watches, at a capped rate) and encodes them on its own thread;
:class:`ViewServer` serves the page, the MJPEG streams and the JSON state with
the standard library's ``ThreadingHTTPServer``. See ``docs/view.md``.
"""

from __future__ import annotations

from .._compat import lazy_attributes

# Loaded on first use: the daemon imports view.thresholds on every start, and must not pay for the
# HTTP server (http.server, email, …) unless daemon.view_port asks for it.
_LAZY = {"Snapshot": ".hub", "ViewHub": ".hub", "ViewServer": ".server", "Thresholds": ".thresholds"}

__all__ = ["Snapshot", "Thresholds", "ViewHub", "ViewServer"]


__getattr__ = lazy_attributes(__name__, _LAZY)
