"""What the capture loop hands its recorder (``run --record``): an interface and a do-nothing one."""

from __future__ import annotations

from typing import Protocol

import numpy as np


class Recorder(Protocol):
    """Takes what the loop saw and sent, without blocking (``recording.background.BackgroundRecorder``)."""

    def add(self, image: np.ndarray, index: int, payload: bytes, t_s: float) -> None:
        """One frame and the reading published for it; ``t_s`` is the reading's ``t`` (Unix s)."""

    def close(self) -> None: ...


class NoRecorder:
    """What the loop records into when nothing was asked for."""

    def add(self, image: np.ndarray, index: int, payload: bytes, t_s: float) -> None:
        pass

    def close(self) -> None:
        pass
