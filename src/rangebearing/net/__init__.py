"""Readings over UDP: wire format v1, publishers and the subscriber library.

The imperative shell's network edge. :mod:`.protocol` is pure (bytes in,
bytes out); :mod:`.publisher` and :mod:`.client` own the sockets.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._compat import lazy_attributes
from .protocol import (
    PROTOCOL_VERSION,
    Reading,
    RemoteLandmark,
    decode_reading,
    encode_reading,
)
from .publisher import MemoryPublisher, Publisher, PublishStats, UdpPublisher

# the subscriber is imported on first use: the daemon (whose config checks import this package) never needs it
_LAZY = {"Subscriber": ".client"}

if TYPE_CHECKING:
    from .client import Subscriber

__getattr__ = lazy_attributes(__name__, _LAZY)

__all__ = [
    "PROTOCOL_VERSION",
    "MemoryPublisher",
    "PublishStats",
    "Publisher",
    "Reading",
    "RemoteLandmark",
    "Subscriber",
    "UdpPublisher",
    "decode_reading",
    "encode_reading",
]
