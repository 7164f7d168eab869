"""The view's HTTP request handler: one instance per request, on the server's thread for that client.

Routes (all under the one host and port)::

    GET  /                    the page (static HTML, JS and CSS shipped in the package)
    GET  /stream.mjpg         multipart/x-mixed-replace JPEGs  ?layer=frame|masks
    GET  /frame.jpg           the newest JPEG                 ?layer=frame|masks
    GET  /api/state           the newest state (landmarks, stats, thresholds) as JSON
    GET  /api/events          the same as server-sent events, one per encoded frame
    GET  /api/thresholds      the thresholds the page controls
    POST /api/thresholds      a JSON object with some of red_hue, blue_hue, s_min, v_min
    POST /api/save            write the thresholds into the config file (FILE.bak kept)

A bad parameter gets 400 with a JSON ``{"error": ...}`` naming it; nothing a
request does can raise into the capture loop. POSTs must be
``application/json`` and same-origin, so another web page open in the same
browser cannot change the thresholds or write the config.
"""

from __future__ import annotations

import contextlib
import json
import logging
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any, Dict, Tuple
from urllib.parse import parse_qs, urlsplit

from ..errors import ConfigError, OutputError, RequestError
from . import thresholds as th
from .hub import LAYERS, ViewHub
from .save import save_thresholds

log = logging.getLogger("rangebearing.view")

MAX_BODY = 64 * 1024
STATIC_TYPES = {".html": "text/html; charset=utf-8", ".js": "text/javascript; charset=utf-8",
                ".css": "text/css; charset=utf-8", ".png": "image/png", ".svg": "image/svg+xml"}
BOUNDARY = b"rangebearingframe"


class _Forbidden(RequestError):
    """A request from another origin (answered 403)."""


class Server(ThreadingHTTPServer):
    """The standard library's threading server, holding the hub and the static files for the handlers."""

    daemon_threads = True  # a browser left open never holds up the exit
    hub: ViewHub
    static: Dict[str, Tuple[bytes, str]]


class Handler(BaseHTTPRequestHandler):
    """One request. Every failure becomes an HTTP answer, never an exception out of the server."""

    server: Server
    server_version = "rangebearing-view"

    def log_message(self, format: str, *args: Any) -> None:
        log.debug("%s %s", self.address_string(), format % args)

    # --- plumbing ----------------------------------------------------------------------------
    def _send(self, status: int, body: bytes, ctype: str, cache: bool = False) -> None:
        self.send_response(status)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "max-age=60" if cache else "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.end_headers()
        self.wfile.write(body)

    def _json(self, status: int, obj: Any) -> None:
        self._send(status, json.dumps(obj).encode("utf-8"), "application/json")

    def _error(self, status: int, message: str) -> None:
        self._json(status, {"error": message})

    def _query(self, allowed: Dict[str, Tuple[str, ...]]) -> Dict[str, str]:
        """The query's parameters, each given once and with an allowed value, else RequestError."""
        q = parse_qs(urlsplit(self.path).query, keep_blank_values=True)
        out = {}
        for key, vals in q.items():
            if key not in allowed:
                raise RequestError(f"unknown parameter {key!r} (known: {', '.join(allowed) or 'none'})")
            if len(vals) != 1 or vals[0] not in allowed[key]:
                raise RequestError(f"{key}: expected one of {', '.join(allowed[key])}, got {vals}")
            out[key] = vals[0]
        return out

    def _dispatch(self, routes: Dict[str, Any]) -> None:
        path = urlsplit(self.path).path
        route = routes.get(path)
        try:
            if route is None:
                name = path.removeprefix("/static/")
                if self.command == "GET" and path.startswith("/static/") and name in self.server.static:
                    self._send(200, *self.server.static[name], cache=True)
                elif path in GET_ROUTES or path in POST_ROUTES:
                    self._error(HTTPStatus.METHOD_NOT_ALLOWED, f"{self.command} is not allowed on {path}")
                else:
                    self._error(HTTPStatus.NOT_FOUND, f"no such page: {path}")
                return
            route(self)
        except RequestError as exc:
            self._error(HTTPStatus.FORBIDDEN if isinstance(exc, _Forbidden) else HTTPStatus.BAD_REQUEST, str(exc))
        except (BrokenPipeError, ConnectionResetError):
            pass  # the browser went away
        except Exception as exc:  # never let a request take anything down with it
            log.exception("view: %s %s failed", self.command, self.path)
            with contextlib.suppress(OSError):
                self._error(HTTPStatus.INTERNAL_SERVER_ERROR, f"{type(exc).__name__}: {exc}")

    def do_GET(self) -> None:
        self._dispatch(GET_ROUTES)

    def do_POST(self) -> None:
        self._dispatch(POST_ROUTES)

    def _body(self) -> Any:
        """The request's JSON body, after the same-origin and size checks."""
        ctype = self.headers.get("Content-Type", "").split(";")[0].strip().lower()
        if ctype != "application/json":
            raise RequestError(f"expected Content-Type application/json, got {ctype or 'none'}")
        origin = self.headers.get("Origin")
        if origin and urlsplit(origin).netloc != self.headers.get("Host"):
            raise _Forbidden(f"cross-origin request from {origin} refused")
        try:
            n = int(self.headers.get("Content-Length", ""))
        except ValueError:
            raise RequestError("Content-Length is missing or not a number") from None
        if not 0 <= n <= MAX_BODY:
            raise RequestError(f"body of {n} bytes (at most {MAX_BODY})")
        raw = self.rfile.read(n)
        try:
            return json.loads(raw.decode("utf-8")) if raw.strip() else {}
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise RequestError(f"body is not valid JSON: {exc}") from None

    # --- routes ------------------------------------------------------------------------------
    def index(self) -> None:
        self._query({})
        self._send(200, *self.server.static["index.html"])

    def stream(self) -> None:
        layer = self._query({"layer": LAYERS}).get("layer", "frame")
        hub = self.server.hub
        self.send_response(200)
        self.send_header("Content-Type", f"multipart/x-mixed-replace; boundary={BOUNDARY.decode()}")
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        # each part is followed at once by the next boundary: browsers show a part when its boundary arrives
        self.wfile.write(b"--%s\r\n" % BOUNDARY)
        seq = 0
        with hub.viewer(layer):
            while not hub.closed:
                snap = hub.wait(seq, 1.0)
                if snap is None:
                    continue
                seq = snap.seq
                data = snap.masks_jpeg if layer == "masks" else snap.jpeg
                if data:
                    head = b"Content-Type: image/jpeg\r\nContent-Length: %d\r\n\r\n" % len(data)
                    self.wfile.write(head + data + b"\r\n--%s\r\n" % BOUNDARY)
                    self.wfile.flush()

    def frame(self) -> None:
        layer = self._query({"layer": LAYERS}).get("layer", "frame")
        hub = self.server.hub
        hub.touch(layer)
        snap = hub.snapshot
        for _ in range(3):  # the newest frame that has this layer, waiting for one if needed
            data = snap.masks_jpeg if layer == "masks" else snap.jpeg
            if data:
                return self._send(200, data, "image/jpeg")
            snap = hub.wait(snap.seq, 1.0) or snap
        self._error(HTTPStatus.SERVICE_UNAVAILABLE, "no frame yet: is the source delivering frames?")

    def state(self) -> None:
        self._query({})
        hub = self.server.hub
        hub.touch()
        snap = hub.snapshot if hub.snapshot.seq else (hub.wait(0, 2.0) or hub.snapshot)
        self._send(200, snap.state, "application/json")

    def events(self) -> None:
        self._query({})
        hub = self.server.hub
        self.send_response(200)
        self.send_header("Content-Type", "text/event-stream")
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        seq = 0
        with hub.viewer():
            while not hub.closed:
                snap = hub.wait(seq, 5.0)
                self.wfile.write(b": keep-alive\n\n" if snap is None else b"data: " + snap.state + b"\n\n")
                self.wfile.flush()
                seq = snap.seq if snap is not None else seq

    def get_thresholds(self) -> None:
        self._query({})
        hub = self.server.hub
        self._json(200, {"thresholds": hub.thresholds.as_json(), "config_file": hub.config_file})

    def post_thresholds(self) -> None:
        self._query({})
        hub = self.server.hub
        new = th.parse(self._body(), hub.thresholds)
        hub.set_thresholds(new)
        log.info("view: thresholds set to %s", new.as_json())
        self._json(200, {"thresholds": new.as_json()})

    def save(self) -> None:
        self._query({})
        self._body()
        hub = self.server.hub
        if not hub.config_file:
            return self._error(HTTPStatus.CONFLICT, "started without --config: there is no file to save to")
        try:
            path, backup = save_thresholds(hub.config_file, hub.thresholds)
        except ConfigError as exc:
            return self._error(HTTPStatus.CONFLICT, str(exc))
        except OutputError as exc:
            return self._error(HTTPStatus.INTERNAL_SERVER_ERROR, str(exc))
        log.info("view: thresholds saved to %s (old file kept as %s)", path, backup)
        self._json(200, {"saved": str(path), "backup": str(backup), "thresholds": hub.thresholds.as_json()})


GET_ROUTES = {
    "/": Handler.index, "/index.html": Handler.index, "/stream.mjpg": Handler.stream, "/frame.jpg": Handler.frame,
    "/api/state": Handler.state, "/api/events": Handler.events, "/api/thresholds": Handler.get_thresholds,
}
POST_ROUTES = {"/api/thresholds": Handler.post_thresholds, "/api/save": Handler.save}


