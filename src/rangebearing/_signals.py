"""Signals that arrive while ``rangebearing run`` is still starting (imports, config loading).

Python's default for SIGHUP ends the process, and the daemon's own handlers can
only be installed once numpy, OpenCV and the config are loaded (about 1.5 s on
a Pi). ``systemctl reload`` right after ``start`` must not kill the service, so
``main`` installs these first, before anything heavy is imported; the daemon
takes over what they noted (:func:`taken_over`). This module imports nothing of
the package.
"""

from __future__ import annotations

import signal
from typing import Any, Dict

_noted: Dict[str, bool] = {"stop": False, "reload": False}


def _note(what: str) -> Any:
    def handler(signum: int, frame: Any) -> None:
        _noted[what] = True

    return handler


def install_early() -> None:
    """SIGTERM and SIGHUP are noted, not fatal, until the daemon installs its handlers."""
    signal.signal(signal.SIGTERM, _note("stop"))
    signal.signal(signal.SIGHUP, _note("reload"))


def taken_over() -> Dict[str, bool]:
    """What arrived early (``{"stop": ..., "reload": ...}``), cleared for the next caller."""
    noted = dict(_noted)
    _noted.update(stop=False, reload=False)
    return noted
