"""The subscriber library: receive and decode readings from rangebearing daemons.

>>> with Subscriber(port=47800, timeout_s=5.0) as sub:      # doctest: +SKIP
...     for reading in sub:
...         for lm in reading.landmarks:
...             print(reading.robot, lm.range_m, lm.bearing_rad)

Datagrams that are not valid v1 readings are dropped and counted in
:attr:`Subscriber.dropped`; receiving never raises on bad input.
"""

from __future__ import annotations

import socket
import time
from typing import Iterator, Optional, Tuple

from ..config import DEFAULT_PORT
from ..config.checks import is_ipv4_multicast
from ..errors import ProtocolError, SubscribeError
from .protocol import Reading, decode_reading

_RECV_BYTES = 65536


def _ipv4(value: str, what: str) -> bytes:
    try:
        return socket.inet_aton(socket.gethostbyname(value))
    except (OSError, UnicodeError) as exc:
        raise SubscribeError(f"{what}: {value!r} is not an IPv4 address or host: {exc}") from None


class ReadingStream:
    """What every subscriber offers on top of its own ``recv_datagram``: readings one by one, or as an iterator.

    Subclasses implement ``recv_datagram(timeout_s) -> (Reading, bytes) | None``.
    """

    def recv_datagram(self, timeout_s: Optional[float] = None) -> Optional[Tuple[Reading, bytes]]:
        raise NotImplementedError

    def recv(self, timeout_s: Optional[float] = None) -> Optional[Reading]:
        """The next valid reading, or ``None`` if none arrives within the timeout."""
        got = self.recv_datagram(timeout_s)
        return None if got is None else got[0]

    def readings(self, timeout_s: Optional[float] = None) -> Iterator[Reading]:
        """Yield readings until one takes longer than the timeout to arrive."""
        while True:
            reading = self.recv(timeout_s)
            if reading is None:
                return
            yield reading

    def __iter__(self) -> Iterator[Reading]:
        return self.readings()


class Subscriber(ReadingStream):
    """A UDP socket bound for readings, unicast or multicast.

    Parameters
    ----------
    port : int
        UDP port; 0 picks a free one (see :attr:`port`).
    host : str
        Local address to bind for unicast; ``"0.0.0.0"`` hears every interface.
    group : str, optional
        IPv4 multicast group to join instead of plain unicast.
    interface : str
        Address of the interface to join the group on.
    timeout_s : float, optional
        Default wait for :meth:`recv` and iteration; ``None`` waits forever.
    """

    def __init__(
        self,
        port: int = DEFAULT_PORT,
        host: str = "127.0.0.1",
        group: Optional[str] = None,
        interface: str = "127.0.0.1",
        timeout_s: Optional[float] = None,
    ) -> None:
        self.timeout_s = timeout_s
        self.group = group or None
        self.dropped = 0
        self.received = 0
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            if self.group is None:
                self._sock.bind((host, port))
            else:
                self._join(self.group, port, interface)
        except BaseException:
            self._sock.close()
            raise

    def _join(self, group: str, port: int, interface: str) -> None:
        if not is_ipv4_multicast(group):
            raise SubscribeError(f"group: {group!r} is not an IPv4 multicast address")
        mreq = _ipv4(group, "group") + _ipv4(interface, "interface")
        # Several listeners on one host may share a group port.
        self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            self._sock.bind((group, port))  # Linux: only this group's datagrams
        except OSError:
            self._sock.bind(("", port))  # Windows cannot bind a group address
        self._sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)

    @property
    def port(self) -> int:
        """The bound UDP port (useful after binding port 0)."""
        return int(self._sock.getsockname()[1])

    @property
    def address(self) -> Tuple[str, int]:
        """The bound ``(host, port)``."""
        host, port = self._sock.getsockname()[:2]
        return str(host), int(port)

    def fileno(self) -> int:
        """The socket's file descriptor, for ``select`` or an event loop."""
        return self._sock.fileno()

    def recv_datagram(self, timeout_s: Optional[float] = None) -> Optional[Tuple[Reading, bytes]]:
        """The next valid reading with the datagram it came from, or ``None`` on timeout.

        ``timeout_s`` defaults to the constructor's; invalid datagrams are
        counted in :attr:`dropped` and do not restart the wait.
        """
        wait_s = self.timeout_s if timeout_s is None else timeout_s
        deadline = None if wait_s is None else time.monotonic() + wait_s
        while True:
            if deadline is None:
                self._sock.settimeout(None)
            else:
                self._sock.settimeout(max(0.0, deadline - time.monotonic()))
            try:
                data, addr = self._sock.recvfrom(_RECV_BYTES)
            except socket.timeout:
                return None
            except BlockingIOError:  # a zero timeout with nothing queued
                return None
            except ConnectionError:  # ICMP errors reported on recv (Windows; Linux with IP_RECVERR)
                continue
            try:
                reading = decode_reading(data, sender=(str(addr[0]), int(addr[1])))
            except ProtocolError:
                self.dropped += 1
                continue
            self.received += 1
            return reading, data

    def close(self) -> None:
        """Leave the group (if any) and close the socket."""
        self._sock.close()

    def __enter__(self) -> Subscriber:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
