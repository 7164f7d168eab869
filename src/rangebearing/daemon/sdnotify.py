"""systemd service notifications (``sd_notify``) in pure stdlib.

systemd passes ``NOTIFY_SOCKET`` to a ``Type=notify`` service: the path of an
``AF_UNIX`` datagram socket, or an abstract-namespace name written with a
leading ``@``.  Each notification is one datagram of newline-separated
``KEY=VALUE`` fields (``READY=1``, ``WATCHDOG=1``, ``STATUS=…``).  Without
``NOTIFY_SOCKET`` (a terminal, a test, a container) every method does nothing.

A notification is best effort: a send that fails is counted and logged, never
raised, and never blocks the capture loop.

Typical use in the daemon::

    notifier = Notifier()
    ...camera opened, first frame read...
    notifier.ready("capturing 640x480 at 30 fps")
    interval_s = notifier.watchdog_interval_s()   # None: no watchdog wanted
    ...each frame, at most every interval_s / 2: notifier.watchdog()
    ...on SIGHUP: notifier.reloading(); reload config; notifier.ready()
    notifier.stopping(); notifier.close()
"""

from __future__ import annotations

import logging
import os
import socket
import time
from typing import Callable, Mapping, Optional, Union

log = logging.getLogger(__name__)

Address = Union[str, bytes]


def notify_address(value: str) -> Optional[Address]:
    """The ``sendto`` address for a ``NOTIFY_SOCKET`` value, or None if unusable.

    ``/run/systemd/notify`` stays a path; ``@name`` becomes the abstract
    address ``b"\\0name"``.  Anything else (empty, relative, ``vsock:``) is None.
    """
    if value.startswith("/"):
        return value
    if value.startswith("@") and len(value) > 1:
        return b"\0" + value[1:].encode("utf-8", "surrogateescape")
    return None


def watchdog_interval_s(environ: Mapping[str, str], pid: int) -> Optional[float]:
    """The watchdog timeout systemd set for process ``pid``, in seconds, or None.

    Mirrors ``sd_watchdog_enabled()``: ``WATCHDOG_USEC`` must be a positive
    integer, and if ``WATCHDOG_PID`` is set it must name ``pid`` (otherwise the
    watchdog belongs to another process, e.g. our parent).  Ping at least
    every half of the returned interval.
    """
    raw = environ.get("WATCHDOG_USEC", "")
    try:
        usec = int(raw)
    except ValueError:
        return None
    if usec <= 0:
        return None
    owner = environ.get("WATCHDOG_PID")
    if owner is not None:
        try:
            if int(owner) != pid:
                return None
        except ValueError:
            return None
    return usec / 1e6


class Notifier:
    """Send ``sd_notify`` messages to systemd; a no-op without ``NOTIFY_SOCKET``.

    Parameters
    ----------
    environ
        Where to read ``NOTIFY_SOCKET``, ``WATCHDOG_USEC`` and ``WATCHDOG_PID``;
        ``os.environ`` when None.
    pid
        This process's id for the ``WATCHDOG_PID`` check; ``os.getpid()`` when None.
    monotonic_ns
        The ``CLOCK_MONOTONIC`` clock for ``MONOTONIC_USEC`` (``time.monotonic_ns``
        is that clock on Linux).

    Attributes
    ----------
    sent, failures
        How many datagrams went out and how many sends failed.
    """

    def __init__(
        self,
        environ: Optional[Mapping[str, str]] = None,
        *,
        pid: Optional[int] = None,
        monotonic_ns: Callable[[], int] = time.monotonic_ns,
    ) -> None:
        self._environ: Mapping[str, str] = os.environ if environ is None else environ
        self._pid = os.getpid() if pid is None else pid
        self._monotonic_ns = monotonic_ns
        self._sock: Optional[socket.socket] = None
        self.sent = 0
        self.failures = 0
        raw = self._environ.get("NOTIFY_SOCKET", "")
        self._address = notify_address(raw) if raw else None
        if raw and self._address is None:
            log.warning("NOTIFY_SOCKET=%r is not a unix socket path or @name; not notifying", raw)

    @property
    def enabled(self) -> bool:
        """True when systemd asked for notifications (a usable ``NOTIFY_SOCKET``)."""
        return self._address is not None

    def notify(self, *fields: str) -> bool:
        """Send ``KEY=VALUE`` fields as one datagram; True if it was sent."""
        if self._address is None or not fields:
            return False
        payload = "\n".join(fields).encode("utf-8", "replace")
        try:
            if self._sock is None:
                sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
                # A full queue must not stall the frame loop: drop and count.
                sock.setblocking(False)
                self._sock = sock
            self._sock.sendto(payload, self._address)
        except OSError as exc:
            self.failures += 1
            level = logging.WARNING if self.failures == 1 else logging.DEBUG
            log.log(level, "sd_notify %r failed (%d so far): %s", fields[0], self.failures, exc)
            return False
        self.sent += 1
        return True

    def ready(self, status: Optional[str] = None) -> bool:
        """Start-up (or a reload) is complete: ``READY=1``, with an optional status."""
        if status is None:
            return self.notify("READY=1")
        return self.notify("READY=1", _status_field(status))

    def watchdog(self) -> bool:
        """Still alive: ``WATCHDOG=1``; call while frames flow."""
        return self.notify("WATCHDOG=1")

    def status(self, text: str) -> bool:
        """A one-line status for ``systemctl status``: ``STATUS=text``."""
        return self.notify(_status_field(text))

    def stopping(self) -> bool:
        """Shutdown has begun: ``STOPPING=1``."""
        return self.notify("STOPPING=1")

    def reloading(self) -> bool:
        """A reload has begun: ``RELOADING=1`` and ``MONOTONIC_USEC`` (systemd >= 253).

        Send :meth:`ready` when the reload is done.
        """
        usec = self._monotonic_ns() // 1000
        return self.notify("RELOADING=1", f"MONOTONIC_USEC={usec}")

    def watchdog_interval_s(self) -> Optional[float]:
        """The watchdog timeout in seconds for this process, or None when disabled."""
        return watchdog_interval_s(self._environ, self._pid)

    def close(self) -> None:
        """Release the socket; later notifications open a new one."""
        if self._sock is not None:
            self._sock.close()
            self._sock = None

    def __enter__(self) -> Notifier:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def _status_field(text: str) -> str:
    # A newline would start a new KEY=VALUE field: keep the status one line.
    return "STATUS=" + " ".join(str(text).splitlines())
