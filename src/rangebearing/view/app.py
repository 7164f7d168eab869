"""Start the view for a capture loop: the hub made from the config, the server on its address."""

from __future__ import annotations

import ipaddress
import logging
import socket
from typing import Any, Optional

from .hub import ViewHub
from .server import ViewServer
from .thresholds import Thresholds

log = logging.getLogger("rangebearing.view")


def is_loopback(host: str) -> bool:
    """True for 127.0.0.0/8, ::1 and names that resolve only to them (``localhost``)."""
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        pass
    try:
        infos = socket.getaddrinfo(host, None)
    except OSError:
        return False
    return bool(infos) and all(ipaddress.ip_address(i[4][0].split("%")[0]).is_loopback for i in infos)


def start_view(
    detection: Any, camera: Any, landmark: Any, host: str, port: int, max_fps: float,
    config_file: Optional[str] = None,
) -> ViewServer:
    """Serve the page for a loop that detects with ``detection`` on frames from ``camera``.

    Raises
    ------
    ServeError
        The address cannot be bound.
    """
    hub = ViewHub(
        Thresholds.of(detection), max_fps=max_fps, config_file=config_file, hfov_rad=camera.hfov_rad,
        band_ratio=landmark.band_height_m / (landmark.height_m - landmark.band_height_m),
    )
    server = ViewServer(hub, host, port).start()
    log.info("view: serving %s (at most %g frames/s while a browser watches)", server.url, max_fps)
    if not is_loopback(host):
        log.warning(
            "view: listening on %s, not loopback: anyone who reaches this port sees the camera and can change "
            "detection; an SSH tunnel (ssh -L %d:127.0.0.1:%d) keeps it private", host, port, port,
        )
    return server
