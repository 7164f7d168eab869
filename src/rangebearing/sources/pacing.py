"""Camera timing for sources that have no camera (recorded and synthetic frames)."""

from __future__ import annotations

import math
from typing import Callable, Optional


class Pacer:
    """Camera timing for sources without a camera: frame *i* is captured at start + i/fps."""

    def __init__(
        self, fps: float, clock: Callable[[], int], sleep: Callable[[float], object]
    ) -> None:
        self.fps = fps
        self._clock = clock
        self._sleep = sleep
        self.start_ns = 0

    def start(self) -> None:
        self.start_ns = self._clock()

    def capture_ns(self, i: int) -> int:
        return self.start_ns + round(i * 1e9 / self.fps)

    def next_index(self, i: int, last: Optional[int] = None) -> int:
        """The frame to deliver when ``i`` is the first one not yet delivered.

        Waits until ``i`` is due if the consumer is early (a ``sleep`` that
        returns True, like ``threading.Event.wait`` once set, ends the wait);
        otherwise returns the newest frame already due (at most ``last``, the
        end of a finite stream), so ``result - i`` frames were dropped.
        """
        now = self._clock()
        due = math.floor((now - self.start_ns) * self.fps / 1e9)
        if due >= i:
            return min(due, max(i, last)) if last is not None else due
        t_due = self.capture_ns(i)
        while now < t_due:
            if self._sleep((t_due - now) / 1e9):
                break
            now = self._clock()
        return i
