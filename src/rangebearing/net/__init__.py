"""Readings over UDP: wire format v1, publishers and the subscriber library.

The imperative shell's network edge. :mod:`.protocol` is pure (bytes in,
bytes out); :mod:`.publisher` and :mod:`.client` own the sockets.
"""

from __future__ import annotations

from .client import Subscriber
from .protocol import (
    PROTOCOL_VERSION,
    Reading,
    RemoteLandmark,
    decode_reading,
    encode_reading,
)
from .publisher import MemoryPublisher, Publisher, PublishStats, UdpPublisher

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
