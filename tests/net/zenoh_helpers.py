"""Zenoh settings for tests: loopback endpoints only, no multicast scouting (nothing leaves the host)."""

from __future__ import annotations

import socket

from rangebearing.net.zenoh_transport import ZenohSettings


def free_tcp_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def hub(port: int) -> ZenohSettings:
    """A peer that listens on 127.0.0.1:port (the controller side)."""
    return ZenohSettings(listen=(f"tcp/127.0.0.1:{port}",), scouting_multicast=False)


def spoke(port: int) -> ZenohSettings:
    """A peer that dials 127.0.0.1:port and itself listens on loopback only."""
    return ZenohSettings(connect=(f"tcp/127.0.0.1:{port}",), listen=("tcp/127.0.0.1:0",),
                         scouting_multicast=False)
