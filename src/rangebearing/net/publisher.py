"""Where encoded readings go: UDP unicast and multicast, or a list in memory.

:class:`UdpPublisher` never lets a network fault escape ``send()``: a dead
receiver, a missing route or a full buffer must not stop the capture loop. Each
fault is counted per destination and errno name (see :attr:`UdpPublisher.stats`)
and logged at most once per destination every ``log_interval_s``.
"""

from __future__ import annotations

import errno
import logging
import socket
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
    try:
        infos = socket.getaddrinfo(host, port, 0, socket.SOCK_DGRAM)
    except (OSError, UnicodeError) as exc:
        raise PublishError(f"{key}: cannot resolve host {host!r}: {exc}") from None
    infos.sort(key=lambda info: info[0] != socket.AF_INET)
    family, _, _, _, sockaddr = infos[0]
    return family, (str(sockaddr[0]), int(sockaddr[1]))


class _Destination:
    """One connected, non-blocking UDP socket; connected so ICMP errors come back to it."""

    def __init__(self, name: str, sock: socket.socket, addr: Tuple[str, int]) -> None:
        self.name = name
        self.sock = sock
        self.addr = addr
        self.connected = False
        self.sent = 0
        self.errors: Dict[str, int] = {}
        self.last_log_s: Optional[float] = None
        self.suppressed = 0

    def send(self, payload: bytes) -> None:
        # Connecting lazily lets the daemon start before the network is up,
        # and reconnecting after an error picks up a changed route or address.
        if not self.connected:
            self.sock.connect(self.addr)
            self.connected = True
        try:
            self.sock.send(payload)
        except OSError:
            self.connected = False
            raise


class UdpPublisher:
    """Sends each payload to every unicast destination and the multicast group.

    Host names are resolved once, here: a name that does not resolve is a
    configuration problem and raises :class:`~rangebearing.errors.PublishError`.
    Multicast goes out of ``multicast_interface`` (``""`` lets the kernel pick)
    with ``multicast_ttl`` and loopback on, so a listener on the same robot hears it.
    """

    def __init__(
        self,
        cfg: PublishConfig,
        logger: Optional[logging.Logger] = None,
        log_interval_s: float = 10.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._log = logger or _log
        self._log_interval_s = log_interval_s
        self._clock = clock
        self._dests: List[_Destination] = []
        self._closed = False
        try:
            for host, port in dict.fromkeys(cfg.unicast):
                family, addr = _resolve(host, port, "publish.unicast")
                self._add(_name(host, port), socket.socket(family, socket.SOCK_DGRAM), addr)
            if cfg.multicast_group:
                self._add_multicast(cfg)
        except BaseException:
            self.close()
            raise

    def _add(self, name: str, sock: socket.socket, addr: Tuple[str, int]) -> None:
        sock.setblocking(False)  # a full buffer is a counted EAGAIN, never a stall
        self._dests.append(_Destination(name, sock, addr))

    def _add_multicast(self, cfg: PublishConfig) -> None:
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
            raise PublishError(f"publish.multicast_interface: cannot send multicast from {iface!r}: {exc}") from None
        self._add(_name(group, port), sock, addr)

    def send(self, payload: bytes) -> None:
        """Send ``payload`` to every destination; faults are counted and logged, not raised."""
        if self._closed:
            return
        for dest in self._dests:
            try:
                dest.send(payload)
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
        self._closed = True
        for dest in self._dests:
            dest.sock.close()

    def __enter__(self) -> UdpPublisher:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
