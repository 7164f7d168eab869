"""Readings over Eclipse Zenoh: session settings, key expressions and the publisher.

The payload is exactly the v1 datagram that goes over UDP (one schema, one
decoder), put with encoding ``application/json`` on ``rangebearing/{robot}/readings``.
While the publisher lives it holds a liveliness token ``rangebearing/{robot}/alive``,
so controllers see robots join and leave; a crash drops the token with the session.

Like :class:`~rangebearing.net.publisher.UdpPublisher`, :class:`ZenohPublisher`
never lets a fault reach the capture loop: the session is opened on a
background thread (a peer dialling an absent endpoint blocks ~0.5 s, a client
with no router fails), sends without a session are dropped and counted, put
errors are counted by kind and logged at most once every ``log_interval_s``.
``eclipse-zenoh`` is an optional extra, imported only when a session is built.
"""

from __future__ import annotations

import contextlib
import json
import logging
import threading
import time
from typing import Any, Callable, Dict, Optional, Sequence

from .._compat import frozen
from ..config import checks as ck
from ..config.schema import ZenohConfig
from ..errors import ConfigError, MissingExtraError, TransportError

_log = logging.getLogger(__name__)

DEFAULT_KEY = "rangebearing/{robot}/readings"
ALIVE_KEY = "rangebearing/{robot}/alive"
MODES = ("peer", "client")


def import_zenoh() -> Any:
    """The ``zenoh`` module, or :class:`MissingExtraError` naming the extra to install."""
    try:
        import zenoh
    except ImportError:
        raise MissingExtraError("zenoh", "eclipse-zenoh", "publishing over Zenoh") from None
    return zenoh


def endpoint_problems(endpoints: Sequence[str], key: str) -> list[str]:
    """What is wrong with each endpoint string (empty list: nothing)."""
    return [f"{key}[{i}]: {e!r} is not a Zenoh endpoint like 'tcp/192.168.1.10:7447'"
            for i, e in enumerate(endpoints) if not isinstance(e, str) or not ck.ENDPOINT.match(e)]


def robot_chunk_problem(robot: str) -> Optional[str]:
    """Why ``robot`` cannot be one chunk of a key expression, or ``None`` when it can."""
    if not ck.is_key_chunk(robot):
        return f"robot id {robot!r} cannot be a Zenoh key chunk (no '/', '*', '$', '?', '#' or spaces)"
    return None


def reading_key(template: str, robot: str) -> str:
    """``template`` with ``{robot}`` filled in (the key a robot publishes on)."""
    return template.replace("{robot}", robot)


def presence_key(readings_key: str) -> str:
    """The liveliness key that goes with a readings key: ``…/readings`` becomes ``…/alive``."""
    head, sep, tail = readings_key.rpartition("/")
    return f"{head}/alive" if sep and tail == "readings" else f"{readings_key}/alive"


@frozen
class ZenohSettings:
    """How to open a Zenoh session (the ``publish.zenoh`` config section, less ``enabled``/``key``)."""

    mode: str = "peer"
    connect: tuple[str, ...] = ()
    listen: tuple[str, ...] = ()  # empty: Zenoh's default for the mode (every interface)
    scouting_multicast: bool = True

    @classmethod
    def from_config(cls, cfg: ZenohConfig) -> ZenohSettings:
        """The session part of a validated ``publish.zenoh`` section."""
        return cls(cfg.mode, tuple(cfg.connect), tuple(cfg.listen), cfg.scouting_multicast)

    def problems(self, where: str = "publish.zenoh") -> list[str]:
        """Every invalid field, named under ``where``."""
        out = [] if self.mode in MODES else [f"{where}.mode: {self.mode!r} is not one of {', '.join(MODES)}"]
        out += endpoint_problems(self.connect, f"{where}.connect")
        out += endpoint_problems(self.listen, f"{where}.listen")
        if self.mode == "client" and not self.connect:
            out.append(f"{where}.connect: client mode needs a router (or peer) endpoint to connect to")
        return out

    def to_json5(self) -> str:
        """The Zenoh configuration these settings stand for."""
        doc: Dict[str, Any] = {
            "mode": self.mode,
            "connect": {"endpoints": list(self.connect)},
            "scouting": {"multicast": {"enabled": bool(self.scouting_multicast)}},
        }
        if self.listen:  # an explicit [] would listen nowhere; leave Zenoh's default instead
            doc["listen"] = {"endpoints": list(self.listen)}
        return json.dumps(doc)

    def zenoh_config(self) -> Any:
        """A ``zenoh.Config``; :class:`ConfigError` for settings Zenoh itself refuses."""
        problems = self.problems()
        if problems:
            raise ConfigError(problems, "publish.zenoh")
        zenoh = import_zenoh()
        try:
            return zenoh.Config.from_json5(self.to_json5())
        except zenoh.ZError as exc:
            raise ConfigError([f"zenoh refuses these settings: {exc}"], "publish.zenoh") from None


def open_session(settings: ZenohSettings) -> Any:
    """Open a ``zenoh.Session``; :class:`TransportError` when Zenoh cannot."""
    zenoh = import_zenoh()
    config = settings.zenoh_config()
    try:
        return zenoh.open(config)
    except zenoh.ZError as exc:
        raise TransportError(f"cannot open a Zenoh session ({settings.mode}): {exc}") from None


@frozen
class ZenohStats:
    """What a :class:`ZenohPublisher` has done: puts, faults by kind, session state."""

    key: str
    sent: int
    errors: Dict[str, int]  # "no-session", "put", "open" -> count
    connected: bool

    @property
    def total_errors(self) -> int:
        return sum(self.errors.values())


class ZenohPublisher:
    """Puts each encoded reading on ``key`` and holds the robot's liveliness token.

    Parameters
    ----------
    robot : str
        The robot id, filled into ``key`` and the liveliness key.
    settings : ZenohSettings
        Mode, endpoints, scouting.
    key : str
        Key expression template; ``{robot}`` is replaced.
    wait_s : float
        How long the constructor waits for the first session (0: do not wait).
    retry_interval_s : float
        Pause between attempts to open a session that failed.
    """

    def __init__(
        self,
        robot: str,
        settings: Optional[ZenohSettings] = None,
        key: str = DEFAULT_KEY,
        wait_s: float = 2.0,
        retry_interval_s: float = 2.0,
        logger: Optional[logging.Logger] = None,
        log_interval_s: float = 10.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        problem = robot_chunk_problem(robot)
        if problem:
            raise ConfigError([f"publish.robot_id: {problem}"], "publish.zenoh")
        self._zenoh = import_zenoh()
        settings = settings or ZenohSettings()
        settings.zenoh_config()  # a bad setting fails here, not on the thread
        self.key = reading_key(key, robot)
        self.alive_key = presence_key(self.key)
        self._settings = settings
        self._retry_s = retry_interval_s
        self._log = logger or _log
        self._log_interval_s = log_interval_s
        self._clock = clock
        self._last_log_s: Optional[float] = None
        self._suppressed = 0
        self._sent = 0
        self._errors: Dict[str, int] = {}
        self._lock = threading.Lock()
        self._ready = threading.Event()
        self._stop = threading.Event()
        self._session: Any = None
        self._publisher: Any = None
        self._token: Any = None
        self._start_connecting()
        if wait_s > 0:
            self._ready.wait(wait_s)

    def _start_connecting(self) -> None:
        self._ready.clear()
        threading.Thread(target=self._connect, name="zenoh-open", daemon=True).start()

    def _connect(self) -> None:
        while not self._stop.is_set():
            try:
                session = open_session(self._settings)
                publisher = session.declare_publisher(
                    self.key, encoding=self._zenoh.Encoding.APPLICATION_JSON,
                    congestion_control=self._zenoh.CongestionControl.DROP, express=True,
                )
                token = session.liveliness().declare_token(self.alive_key)
            except (TransportError, self._zenoh.ZError) as exc:
                self._fault("open", exc)
                self._stop.wait(self._retry_s)
                continue
            with self._lock:
                if self._stop.is_set():  # closed while opening
                    session.close()
                    return
                self._session, self._publisher, self._token = session, publisher, token
            self._ready.set()
            return

    def send(self, payload: bytes) -> None:
        """Put ``payload``; no session yet or a failed put is counted and logged, never raised."""
        publisher = self._publisher
        if publisher is None:
            if not self._stop.is_set():
                self._count("no-session")
            return
        try:
            publisher.put(payload)
        except self._zenoh.ZError as exc:
            self._fault("put", exc)
            self._reopen_if_closed()
        else:
            self._sent += 1

    def _reopen_if_closed(self) -> None:
        with self._lock:
            session = self._session
            if session is None or self._stop.is_set() or not session.is_closed():
                return
            self._session = self._publisher = self._token = None
        self._start_connecting()

    def _count(self, kind: str) -> None:
        self._errors[kind] = self._errors.get(kind, 0) + 1

    def _fault(self, kind: str, exc: BaseException) -> None:
        self._count(kind)
        now = self._clock()
        if self._last_log_s is not None and now - self._last_log_s < self._log_interval_s:
            self._suppressed += 1
            return
        since = f" ({self._suppressed} more errors since the last report)" if self._suppressed else ""
        self._log.warning("zenoh %s on %s failed: %s%s", kind, self.key, exc, since)
        self._last_log_s = now
        self._suppressed = 0

    def wait_connected(self, timeout_s: Optional[float] = None) -> bool:
        """Block until the session is open (True) or the timeout passes (False)."""
        return self._ready.wait(timeout_s)

    @property
    def stats(self) -> ZenohStats:
        """Puts, faults by kind and whether a session is open."""
        return ZenohStats(self.key, self._sent, dict(self._errors), self._publisher is not None)

    def close(self) -> None:
        """Withdraw the liveliness token and close the session; later sends do nothing."""
        self._stop.set()
        with self._lock:
            session, self._publisher = self._session, None
            token, self._token, self._session = self._token, None, None
        for undo in (getattr(token, "undeclare", None), getattr(session, "close", None)):
            if undo is None:
                continue
            with contextlib.suppress(self._zenoh.ZError):  # already closed underneath us
                undo()

    def __enter__(self) -> ZenohPublisher:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
