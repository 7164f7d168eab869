"""Several publishers as one: UDP and Zenoh side by side, and one Zenoh session kept across reloads."""

from __future__ import annotations

from typing import Optional, Sequence

from .publisher import Publisher


class FanOut:
    """Sends each payload through several publishers (UDP and Zenoh), each with its own fault rule."""

    def __init__(self, publishers: Sequence[Publisher]) -> None:
        self.publishers = tuple(publishers)

    def send(self, payload: bytes) -> None:
        for pub in self.publishers:
            pub.send(payload)

    def close(self) -> None:
        for pub in self.publishers:
            pub.close()


class Shared:
    """One publisher handed to several owners (old and new config across a reload).

    Each :meth:`handle` is closed by its owner; the publisher itself closes with
    the last handle, so a Zenoh session and its presence token outlive a reload.
    """

    def __init__(self, inner: Publisher) -> None:
        self.inner = inner
        self._owners = 0

    def handle(self) -> Publisher:
        self._owners += 1
        return _Handle(self)

    def _release(self) -> None:
        self._owners -= 1
        if self._owners == 0:
            self.inner.close()


class _Handle:
    def __init__(self, shared: Shared) -> None:
        self._shared: Optional[Shared] = shared

    def send(self, payload: bytes) -> None:
        if self._shared is not None:
            self._shared.inner.send(payload)

    def close(self) -> None:
        shared, self._shared = self._shared, None
        if shared is not None:
            shared._release()
