"""Where encoded readings go: UDP unicast and multicast, or a list in memory.

:class:`UdpPublisher` never lets a network fault escape ``send()``: a dead
receiver, a missing route or a full buffer must not stop the capture loop. Each
fault is counted per destination and errno name (see :attr:`UdpPublisher.stats`)
and logged at most once per destination every ``log_interval_s``. A destination
that cannot be set up yet (its host does not resolve) is retried in the background.
"""

from __future__ import annotations

import errno
import functools
import logging
import socket
import threading
import time
from typing import Callable, Dict, List, Optional, Protocol, Tuple

from .._compat import frozen
from ..config import PublishConfig
from ..errors import PublishError

_log = logging.getLogger(__name__)


class Publisher(Protocol):
    """Sends one encoded reading somewhere; never raises on network faults."""

    def send(self, payload: bytes) -> None: ...

    def close(self) -> None: ...


class MemoryPublisher:
    """Keeps every payload in :attr:`payloads`, for tests and dry runs."""

    def __init__(self) -> None:
        self.payloads: List[bytes] = []
        self.closed = False

    def send(self, payload: bytes) -> None:
        self.payloads.append(bytes(payload))

    def close(self) -> None:
        self.closed = True


@frozen
class PublishStats:
    """A snapshot of what a :class:`UdpPublisher` has done, keyed by ``"host:port"``."""

    sent: Dict[str, int]
    errors: Dict[str, Dict[str, int]]  # destination -> errno name -> count

    @property
    def total_sent(self) -> int:
        return sum(self.sent.values())

    @property
    def total_errors(self) -> int:
        return sum(sum(by_name.values()) for by_name in self.errors.values())


def _errno_name(exc: OSError) -> str:
    return errno.errorcode.get(exc.errno or 0, type(exc).__name__)


def _name(host: str, port: int) -> str:
    return f"[{host}]:{port}" if ":" in host else f"{host}:{port}"


def _resolve(host: str, port: int, key: str) -> Tuple[int, Tuple[str, int]]:
    """The address family and socket address of ``host``, preferring IPv4."""
    for family in (socket.AF_INET, socket.AF_INET6):  # an address literal needs no resolver (nor its idna codec,
        try:                                           # its NSS modules: ~5 ms at the first call)
            socket.inet_pton(family, host)
            return family, (host, port)
        except (OSError, ValueError):  # not a literal of this family (ValueError: a NUL)
            continue
    try:
        infos = socket.getaddrinfo(host, port, 0, socket.SOCK_DGRAM)
    except (OSError, UnicodeError) as exc:
        raise PublishError(f"{key}: cannot resolve host {host!r}: {exc}") from None
    infos.sort(key=lambda info: info[0] != socket.AF_INET)
    family, _, _, _, sockaddr = infos[0]
    return family, (str(sockaddr[0]), int(sockaddr[1]))


Setup = Callable[[], Tuple[socket.socket, Tuple[str, int]]]


class _Destination:
    """One connected, non-blocking UDP socket; connected so ICMP errors come back to it.

    ``sock`` is ``None`` while the destination is pending (its host did not
    resolve yet, or its interface is not up): ``setup`` is retried in the background.
    """

    def __init__(self, name: str, setup: Setup) -> None:
        self.name = name
        self.setup = setup
        self.sock: Optional[socket.socket] = None
        self.addr: Tuple[str, int] = ("", 0)
        self.connected = False
        self.sent = 0
        self.errors: Dict[str, int] = {}
        self.last_log_s: Optional[float] = None
        self.suppressed = 0
        self.problem = ""  # why it is pending

    def send(self, payload: bytes) -> None:
        # Connecting lazily lets the daemon start before the network is up,
        # and reconnecting after an error picks up a changed route or address.
        sock = self.sock
        if sock is None:
            raise _Pending()
        if not self.connected:
            sock.connect(self.addr)
            self.connected = True
        try:
            sock.send(payload)
        except OSError:
            self.connected = False
            raise


class _Pending(OSError):
    """A send to a destination that is not set up yet (counted as UNRESOLVED)."""


class UdpPublisher:
    """Sends each payload to every unicast destination and the multicast group.

    A destination whose host does not resolve (a typo, or DNS not up yet at
    boot) or whose multicast interface is not up yet does not stop the others:
    it is logged, its sends are counted as ``UNRESOLVED``, and a background
    thread retries it with back-off (``retry_s`` doubling to ``max_retry_s``)
    until it works or the publisher is closed. Multicast goes out of
    ``multicast_interface`` (``""`` lets the kernel pick) with ``multicast_ttl``
    and loopback on, so a listener on the same robot hears it.
    """

    def __init__(
        self,
        cfg: PublishConfig,
        logger: Optional[logging.Logger] = None,
        log_interval_s: float = 10.0,
        clock: Callable[[], float] = time.monotonic,
        retry_s: float = 1.0,
        max_retry_s: float = 30.0,
    ) -> None:
        self._log = logger or _log
        self._log_interval_s = log_interval_s
        self._clock = clock
        self._dests: List[_Destination] = []
        self._closed = False
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._retry_s, self._max_retry_s = retry_s, max_retry_s
        for host, port in dict.fromkeys(cfg.unicast):
            self._dests.append(_Destination(_name(host, port), functools.partial(_unicast, host, port)))
        if cfg.multicast_group:
            group, port = cfg.multicast_group, cfg.multicast_port
            self._dests.append(_Destination(_name(group, port), functools.partial(_multicast, cfg)))
        for dest in self._dests:
            self._try_setup(dest, first=True)
        self._retrier: Optional[threading.Thread] = None
        if self.pending:
            self._retrier = threading.Thread(target=self._retry_pending, name="publish-resolver", daemon=True)
            self._retrier.start()

    def _try_setup(self, dest: _Destination, first: bool = False) -> bool:
        try:
            sock, addr = dest.setup()
        except PublishError as exc:
            problem = str(exc)
        except OSError as exc:  # EMFILE, ENOBUFS: try again later too
            problem = f"{dest.name}: cannot open a socket: {exc.strerror or exc}"
        else:
            sock.setblocking(False)  # a full buffer is a counted EAGAIN, never a stall
            with self._lock:
                if self._closed:
                    sock.close()
                    return True
                dest.addr, dest.sock = addr, sock
            if not first:
                self._log.warning("publishing to %s now (%s:%d)", dest.name, *addr)
            return True
        if first or problem != dest.problem:
            self._log.warning("%s; sending to the other destinations and retrying it", problem)
        dest.problem = problem
        return False

    def _retry_pending(self) -> None:
        delay = self._retry_s
        while not self._wake.wait(delay):
            pending = [d for d in self._dests if d.sock is None]
            if not pending:
                return
            for dest in pending:
                if self._closed:
                    return
                self._try_setup(dest)
            delay = min(delay * 2.0, self._max_retry_s)

    @property
    def pending(self) -> Tuple[str, ...]:
        """Destinations not set up yet (host not resolved, interface not up), with the reason."""
        return tuple(d.problem for d in self._dests if d.sock is None)

    def send(self, payload: bytes) -> None:
        """Send ``payload`` to every destination; faults are counted and logged, not raised."""
        if self._closed:
            return
        for dest in self._dests:
            try:
                dest.send(payload)
            except _Pending:
                dest.errors["UNRESOLVED"] = dest.errors.get("UNRESOLVED", 0) + 1
            except OSError as exc:
                self._fault(dest, exc)
            else:
                dest.sent += 1

    def _fault(self, dest: _Destination, exc: OSError) -> None:
        name = _errno_name(exc)
        dest.errors[name] = dest.errors.get(name, 0) + 1
        now = self._clock()
        if dest.last_log_s is not None and now - dest.last_log_s < self._log_interval_s:
            dest.suppressed += 1
            return
        since = f" ({dest.suppressed} more errors since the last report)" if dest.suppressed else ""
        self._log.warning("udp send to %s failed: %s %s%s", dest.name, name, exc.strerror or exc,
                          since)
        dest.last_log_s = now
        dest.suppressed = 0

    @property
    def destinations(self) -> Tuple[str, ...]:
        """Every destination as ``"host:port"``, unicast first, multicast last."""
        return tuple(d.name for d in self._dests)

    @property
    def stats(self) -> PublishStats:
        """Datagrams sent and errors by errno name, per destination."""
        return PublishStats(
            sent={d.name: d.sent for d in self._dests},
            errors={d.name: dict(d.errors) for d in self._dests if d.errors},
        )

    def close(self) -> None:
        """Close every socket; later sends do nothing. Safe to call twice."""
        with self._lock:
            self._closed = True
            socks = [d.sock for d in self._dests if d.sock is not None]
        self._wake.set()
        for sock in socks:
            sock.close()

    def __enter__(self) -> UdpPublisher:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _unicast(host: str, port: int) -> Tuple[socket.socket, Tuple[str, int]]:
    family, addr = _resolve(host, port, "publish.unicast")
    return socket.socket(family, socket.SOCK_DGRAM), addr


def _multicast(cfg: PublishConfig) -> Tuple[socket.socket, Tuple[str, int]]:
    group, port = cfg.multicast_group, cfg.multicast_port
    _, addr = _resolve(group, port, "publish.multicast_group")
    iface = "0.0.0.0"
    if cfg.multicast_interface:
        _, (iface, _) = _resolve(cfg.multicast_interface, 0, "publish.multicast_interface")
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, cfg.multicast_ttl)
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(iface))
    except OSError as exc:
        sock.close()
        raise PublishError(
            f"publish.multicast_interface: cannot send multicast from {iface!r} (not up yet?): {exc}"
        ) from None
    return sock, addr
