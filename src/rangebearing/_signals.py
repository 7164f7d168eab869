"""Signals that arrive while ``rangebearing run`` is still starting (imports, config loading).

Python's default for SIGHUP ends the process, and the daemon's own handlers can
only be installed once numpy, OpenCV and the config are loaded (about 1.5 s on
a Pi). ``systemctl reload`` right after ``start`` must not kill the service, so
``main`` installs these first, before anything heavy is imported; the daemon
takes over what they noted (:func:`taken_over`). This module imports nothing of
the package.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from typing import Any, Callable, Dict, Optional

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


class Relay:
    """Signals acted on in a thread of their own, never inside the handler.

    A Python signal handler runs in the main thread between any two bytecodes,
    also while that thread holds a lock: ``Event.set`` from a handler deadlocks
    when the signal lands inside the same event's ``clear()`` or ``wait()`` (a
    SIGHUP storm against the loop's reload flag did exactly that). The handler
    here only writes the signal's number to a pipe (no lock, no allocation to
    speak of); a daemon thread reads it and calls the action, where taking a
    lock is an ordinary wait. One a process (:func:`handle`).
    """

    def __init__(self) -> None:
        self._actions: Dict[int, Callable[[], None]] = {}
        self._r, self._w = os.pipe()
        os.set_blocking(self._w, False)
        self._pending: Dict[int, bool] = {}  # a pipe that is full (64 KiB of signals) still loses none
        threading.Thread(target=self._run, name="signals", daemon=True).start()

    def handle(self, actions: Dict[int, Callable[[], None]]) -> None:
        self._actions.update(actions)
        for signum in actions:
            signal.signal(signum, self._handler)

    def _handler(self, signum: int, frame: Any) -> None:
        self._pending[signum] = True
        with contextlib.suppress(OSError):  # full: the thread is behind and will see _pending
            os.write(self._w, bytes((signum,)))

    def _run(self) -> None:
        while True:
            try:
                data = os.read(self._r, 256)
            except OSError:
                return
            if not data:
                return
            for signum in dict.fromkeys(data):  # each signal once a batch, in order
                if self._pending.pop(signum, False) and signum in self._actions:
                    try:
                        self._actions[signum]()
                    except Exception:  # an action's bug must not end the relay: later signals would be lost
                        _log_failure(signum)


def _log_failure(signum: int) -> None:
    import logging  # here, in the relay thread (never in a handler); this module imports nothing heavy at start

    logging.getLogger("rangebearing").exception("the action for signal %d failed", signum)


_relay: Optional[Relay] = None


def handle(actions: Dict[int, Callable[[], None]]) -> None:
    """Call ``actions[signum]()`` on each signal, from the process's relay thread (installed from the main thread)."""
    global _relay
    if _relay is None:
        _relay = Relay()
    _relay.handle(actions)
