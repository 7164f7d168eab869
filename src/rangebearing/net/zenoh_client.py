"""The Zenoh subscriber library: readings and presence from every robot on a key expression.

>>> from rangebearing.net.zenoh_transport import ZenohSettings   # doctest: +SKIP
>>> with ZenohSubscriber(settings=ZenohSettings(connect=("tcp/10.0.0.1:7447",))) as sub:
...     for reading in sub:
...         print(reading.robot, [lm.range_m for lm in reading.landmarks])

It hands out the same :class:`~rangebearing.net.protocol.Reading` objects and
``received``/``dropped`` counters as the UDP :class:`~rangebearing.net.client.Subscriber`:
samples that are not valid v1 readings are dropped and counted, receiving never
raises on bad input. Presence comes from the robots' liveliness tokens
(``rangebearing/{robot}/alive``) as :class:`PresenceEvent` objects.
"""

from __future__ import annotations

import queue
import threading
import time
import weakref
from typing import Any, Optional, Set, Tuple

from .._compat import frozen
from ..errors import ConfigError, ProtocolError
from .client import ReadingStream
from .protocol import Reading, decode_reading
from .zenoh_transport import ZenohSettings, import_zenoh, open_session, presence_key

DEFAULT_SUBSCRIBE_KEY = "rangebearing/*/readings"
_QUEUE_SAMPLES = 10_000  # about a minute of 10 robots at 15 fps
_OPEN: weakref.WeakSet = weakref.WeakSet()


def _close_all() -> None:
    for sub in list(_OPEN):
        sub.close()


# Zenoh runs Python callbacks on threads that live as long as the session, and the
# interpreter joins threads *before* atexit handlers run: a subscriber left open
# would hang the exit. threading's own pre-join hook (as concurrent.futures uses) closes it.
_register = getattr(threading, "_register_atexit", None)
if _register is not None:
    _register(_close_all)


@frozen
class PresenceEvent:
    """A robot's liveliness token appeared (``alive``) or went away; ``t`` is local Unix time."""

    robot: str
    alive: bool
    t: float


def _robot_of(key: str) -> str:
    """``rangebearing/zumo3/alive`` → ``zumo3``: the chunk before the last one."""
    parts = key.split("/")
    return parts[-2] if len(parts) >= 2 else key


class ZenohSubscriber(ReadingStream):
    """Subscribes to readings (and presence) on a Zenoh key expression.

    Parameters
    ----------
    key : str
        Readings key expression: ``rangebearing/*/readings`` hears every robot,
        ``rangebearing/zumo3/readings`` one, ``rangebearing/{a,b}/readings`` is *not*
        Zenoh syntax (declare several subscribers instead).
    settings : ZenohSettings
        How to join the network (peer or client, endpoints, scouting).
    timeout_s : float, optional
        Default wait for :meth:`recv` and iteration; ``None`` waits forever.
    presence : bool
        Also follow the liveliness tokens that go with ``key``.
    """

    def __init__(
        self,
        key: str = DEFAULT_SUBSCRIBE_KEY,
        settings: Optional[ZenohSettings] = None,
        timeout_s: Optional[float] = None,
        presence: bool = True,
    ) -> None:
        zenoh = import_zenoh()
        self.key = key
        self.timeout_s = timeout_s
        self.received = 0
        self.dropped = 0
        self.overflowed = 0  # samples lost because nobody called recv for a long time
        self._samples: queue.Queue[Tuple[bytes, str]] = queue.Queue(_QUEUE_SAMPLES)
        self._presence: queue.Queue[PresenceEvent] = queue.Queue()
        self._alive: Set[str] = set()
        self._lock = threading.Lock()
        self._session = open_session(settings or ZenohSettings())
        try:
            self._sub = self._session.declare_subscriber(key, self._on_sample)
            self._live = None
            if presence:
                self._live = self._session.liveliness().declare_subscriber(
                    presence_key(key), self._on_token, history=True)
        except zenoh.ZError as exc:
            self._session.close()
            raise ConfigError([f"zenoh key {key!r}: {exc}"], "subscriber") from None
        self._put_kind = zenoh.SampleKind.PUT
        _OPEN.add(self)

    def _on_sample(self, sample: Any) -> None:  # a Zenoh thread
        try:
            self._samples.put_nowait((sample.payload.to_bytes(), str(sample.key_expr)))
        except queue.Full:
            self.overflowed += 1

    def _on_token(self, sample: Any) -> None:  # a Zenoh thread
        robot = _robot_of(str(sample.key_expr))
        alive = sample.kind == self._put_kind
        with self._lock:
            (self._alive.add if alive else self._alive.discard)(robot)
        self._presence.put(PresenceEvent(robot, alive, time.time()))

    @property
    def alive(self) -> Set[str]:
        """Robots whose liveliness token is present right now."""
        with self._lock:
            return set(self._alive)

    def recv_presence(self, timeout_s: Optional[float] = 0.0) -> Optional[PresenceEvent]:
        """The next join/leave event, or ``None`` if none comes within ``timeout_s`` (0: poll)."""
        try:
            if timeout_s is not None and timeout_s <= 0:
                return self._presence.get_nowait()
            return self._presence.get(timeout=timeout_s)
        except queue.Empty:
            return None

    def recv_datagram(self, timeout_s: Optional[float] = None) -> Optional[Tuple[Reading, bytes]]:
        """The next valid reading with the payload it came from, or ``None`` on timeout.

        ``timeout_s`` defaults to the constructor's; invalid payloads are counted
        in :attr:`dropped` and do not restart the wait.
        """
        wait_s = self.timeout_s if timeout_s is None else timeout_s
        deadline = None if wait_s is None else time.monotonic() + wait_s
        while True:
            try:
                if deadline is None:
                    data, _ = self._samples.get()
                else:
                    data, _ = self._samples.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                return None
            try:
                reading = decode_reading(data)
            except ProtocolError:
                self.dropped += 1
                continue
            self.received += 1
            return reading, data

    def close(self) -> None:
        """Undeclare the subscribers and close the session. Safe to call twice."""
        if not self._session.is_closed():
            self._session.close()

    def __enter__(self) -> ZenohSubscriber:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
