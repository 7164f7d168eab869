"""``rangebearing view``: a live web page of what the robot sees, served by the robot.

:class:`ViewHub` takes frames from the capture loop (only while a browser
watches, at a capped rate) and encodes them on its own thread;
:class:`ViewServer` serves the page, the MJPEG streams and the JSON state with
the standard library's ``ThreadingHTTPServer``. See ``docs/view.md``.
"""

from .hub import Snapshot, ViewHub
from .server import ViewServer
from .thresholds import Thresholds

__all__ = ["Snapshot", "Thresholds", "ViewHub", "ViewServer"]
