"""Running statistics of the capture loop: rates, drops, per-stage time, latency."""

from __future__ import annotations

import collections
from typing import Deque, Dict

import numpy as np

from .._compat import frozen
from ..core.stats import percentile


@frozen
class Summary:
    """A snapshot of the loop's figures (times in milliseconds)."""

    frames: int
    bad_frames: int
    dropped: int
    fps: float
    landmarks: int
    latency_ms_p50: float
    latency_ms_p99: float
    stage_ms: Dict[str, float]
    pipeline_cpu_ms: float = 0.0  # mean CPU time of the pipeline per frame (the detector's share of the daemon)
    tracked_pct: float = 0.0  # frames processed by tracking rather than a full scan

    def line(self) -> str:
        stages = " ".join(f"{k}={v:.2f}" for k, v in self.stage_ms.items())
        return (
            f"{self.frames} frames, {self.fps:.1f} fps, {self.landmarks} in view, "
            f"dropped {self.dropped}, bad {self.bad_frames}, "
            f"latency p50 {self.latency_ms_p50:.2f} ms p99 {self.latency_ms_p99:.2f} ms, stage ms {stages}, "
            f"pipeline CPU {self.pipeline_cpu_ms:.3f} ms/frame ({self.tracked_pct:.0f} % tracked)"
        )


class LoopStats:
    """Counts and timings; keeps the last ``window`` samples for percentiles."""

    def __init__(self, window: int = 4096) -> None:
        self.frames = 0
        self.bad_frames = 0
        self.landmarks = 0
        self.latency_ns: Deque[int] = collections.deque(maxlen=window)
        self.stage_ns: Dict[str, Deque[int]] = {}
        self._window = window
        self._done_ns: Deque[int] = collections.deque(maxlen=64)
        self.cpu_ns: Deque[int] = collections.deque(maxlen=window)
        self.tracked: Deque[bool] = collections.deque(maxlen=window)

    def frame_done(self, now_ns: int, latency_ns: int, landmarks: int, stages_ns: Dict[str, int],
                   cpu_ns: int = 0, tracked: bool = False) -> None:
        """One frame sent: ``cpu_ns`` is the pipeline's CPU time for it, ``tracked`` whether it was a tracked frame."""
        self.frames += 1
        self.landmarks = landmarks
        self.latency_ns.append(latency_ns)
        for name, ns in stages_ns.items():
            self.stage_ns.setdefault(name, collections.deque(maxlen=self._window)).append(ns)
        self._done_ns.append(now_ns)
        self.cpu_ns.append(cpu_ns)
        self.tracked.append(tracked)

    @property
    def fps(self) -> float:
        """Frames per second over the last 64 frames."""
        d = self._done_ns
        return (len(d) - 1) * 1e9 / (d[-1] - d[0]) if len(d) > 1 and d[-1] > d[0] else 0.0

    def summary(self, dropped: int) -> Summary:
        # core.stats.percentile: numpy's linear percentile by a partial sort (np.percentile costs ~1.5 ms on
        # 4,096 samples in the loop's thread, and its first call imports numpy.ma: a ~16 ms stall)
        lat = np.fromiter(self.latency_ns, np.int64, len(self.latency_ns)) / 1e6
        p50, p99 = (percentile(lat, 50), percentile(lat, 99)) if lat.size else (0.0, 0.0)
        stages = {k: percentile(np.fromiter(v, np.int64, len(v)) / 1e6, 50) for k, v in self.stage_ns.items() if v}
        n = len(self.cpu_ns)
        cpu_ms = sum(self.cpu_ns) / n / 1e6 if n else 0.0
        tracked = 100.0 * sum(self.tracked) / n if n else 0.0
        return Summary(self.frames, self.bad_frames, dropped, self.fps, self.landmarks, p50, p99, stages, cpu_ms,
                       tracked)
