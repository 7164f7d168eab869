"""The view's web server: the standard library's ``ThreadingHTTPServer``, one thread per client.

It serves the page (static files shipped in the package), the MJPEG streams,
the JSON state and server-sent events, and takes threshold changes; the routes
are in :mod:`.handler`.
"""

from __future__ import annotations

import socket
import threading
from importlib import resources
from typing import Dict, Optional, Tuple

from ..errors import ServeError
from .handler import STATIC_TYPES, Handler, Server
from .hub import ViewHub


def _static_files() -> Dict[str, Tuple[bytes, str]]:
    """Every file of the package's ``static/`` folder, read once: name → (bytes, content type)."""
    out = {}
    for entry in resources.files(__package__).joinpath("static").iterdir():
        suffix = "." + entry.name.rpartition(".")[2]
        if entry.is_file() and suffix in STATIC_TYPES:
            out[entry.name] = (entry.read_bytes(), STATIC_TYPES[suffix])
    return out


class _Server6(Server):
    address_family = socket.AF_INET6


class ViewServer:
    """The page and its streams for one :class:`ViewHub`, served from a background thread.

    Raises
    ------
    ServeError
        The address cannot be bound (in use, not an address of this machine).
    """

    def __init__(self, hub: ViewHub, host: str = "127.0.0.1", port: int = 8080) -> None:
        cls = _Server6 if ":" in host else Server
        try:
            self._httpd = cls((host, port), Handler)
        except OSError as exc:
            raise ServeError(f"view: cannot listen on {host}:{port}: {exc.strerror or exc}") from None
        self._httpd.hub = hub
        self._httpd.static = _static_files()
        self.hub = hub
        self._thread: Optional[threading.Thread] = None

    @property
    def address(self) -> Tuple[str, int]:
        return self._httpd.server_address[:2]  # type: ignore[return-value]

    @property
    def url(self) -> str:
        host, port = self.address
        return f"http://[{host}]:{port}/" if ":" in host else f"http://{host}:{port}/"

    def start(self) -> ViewServer:
        """Start the encoder thread and serve in a background thread."""
        self.hub.start()
        self._thread = threading.Thread(
            target=self._httpd.serve_forever, args=(0.1,), name="rangebearing-view", daemon=True
        )
        self._thread.start()
        return self

    def close(self) -> None:
        """Stop serving, end every stream, release the port."""
        self.hub.close()
        if self._thread is not None:
            self._httpd.shutdown()
            self._thread.join(timeout=5.0)
        self._httpd.server_close()

    def __enter__(self) -> ViewServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()
