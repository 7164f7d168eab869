"""The daemon's capture → send path in CPU time, which a busy machine cannot blur: ``daemon.scan_after_send`` off/on.

``bench_daemon.py`` measures the daemon from outside in wall time: on a shared machine its latency is the
scheduler's. This runs the same loop in-process on the same clip, paced, and stamps the loop thread's CPU clock
when a frame has been read and when its datagram is handed to the socket: the CPU a frame costs before its
reading is out (what capture → send takes on a core of its own), and the CPU a frame costs in all (the scan
after the send included). Modes alternate within each round.

    python benchmarks/bench_send_path.py --fps 90 --seconds 6 --rounds 3
"""

from __future__ import annotations

import argparse
import dataclasses
import gc
import os
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Dict, List, Sequence

import cv2
import numpy as np

from rangebearing.config import Config, PublishConfig, SourceConfig
from rangebearing.core.stats import percentile
from rangebearing.daemon.loop import Daemon
from rangebearing.daemon.process import THRESHOLDS
from rangebearing.sources.factory import open_source


class _Stamped:
    """A frame source whose ``read`` notes the thread's CPU clock as it returns."""

    def __init__(self, source: Any, marks: List[int]) -> None:
        self._source, self._marks = source, marks

    def read(self) -> Any:
        frame = self._source.read()
        self._marks.append(time.thread_time_ns())
        return frame

    def __getattr__(self, name: str) -> Any:
        return getattr(self._source, name)


class _Publisher:
    """Notes the thread's CPU clock as each datagram goes out (to nowhere: the loop's own cost only)."""

    def __init__(self, marks: List[int]) -> None:
        self.marks = marks

    def send(self, payload: bytes) -> None:
        self.marks.append(time.thread_time_ns())

    def close(self) -> None:
        pass


class _Quiet:
    def ready(self, status=None) -> None: ...
    def watchdog(self) -> None: ...
    def status(self, text) -> None: ...
    def stopping(self) -> None: ...
    def reloading(self) -> None: ...
    def watchdog_interval_s(self) -> None:
        return None


def run_once(cfg: Config, clip: Path, fps: float, seconds: float, later: bool, skip: int) -> Dict[str, float]:
    run_cfg = dataclasses.replace(
        cfg, source=SourceConfig(kind="recorded", path=str(clip), fps=fps, loop=True),
        publish=PublishConfig(robot_id="bench", unicast=(("127.0.0.1", 9),)),
        daemon=dataclasses.replace(cfg.daemon, scan_after_send=later))
    reads: List[int] = []
    pub = _Publisher([])

    def opener(c: Config, sleep: Any) -> Any:
        return _Stamped(open_source(c.source, c.camera, sleep=sleep, in_place=True), reads)

    # as `rangebearing run` builds it: start-up frozen, the collector after the send, no timer slack
    daemon = Daemon(run_cfg, opener, lambda c: pub, _Quiet(), freeze_gc=True)
    timer = threading.Timer(seconds, daemon.stop)
    timer.start()
    c0 = time.thread_time_ns()
    try:
        daemon.run()
    finally:
        gc.unfreeze()  # the next round starts as this one did
        gc.set_threshold(*THRESHOLDS)
    total_ns = time.thread_time_ns() - c0
    timer.cancel()
    n = min(len(reads), len(pub.marks))
    to_send = np.array(pub.marks[skip:n]) - np.array(reads[skip:n])
    # what happened after the send (the scan, bookkeeping) until the next read started is in the per-frame total
    per_frame = np.diff(np.array(reads[skip:n]))
    lat = np.fromiter(daemon.stats.latency_ns, np.int64)[skip:] / 1e6
    summary = daemon.summary()
    return {
        "frames": float(n - skip), "dropped": float(summary.dropped),
        "send_p50": percentile(to_send / 1e6, 50), "send_p99": percentile(to_send / 1e6, 99),
        "send_max": float(to_send.max() / 1e6),
        "frame_cpu_ms": float(per_frame.mean() / 1e6), "all_cpu_ms": total_ns / 1e6 / max(1, n),
        "wall_p50": percentile(lat, 50), "wall_p99": percentile(lat, 99),
        "tracked_pct": summary.tracked_pct,
    }


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="bench_send_path.py", description=__doc__.splitlines()[0])
    p.add_argument("--fps", type=float, default=90.0)
    p.add_argument("--seconds", type=float, default=6.0)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--frames", type=int, default=60)
    args = p.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from bench_daemon import bench_clip

    cfg, frames = bench_clip(args.frames)
    print("| scan after send | frames | dropped | CPU to send p50 / p99 / max ms | CPU ms a frame (loop thread) "
          "| wall capture→send p50 / p99 ms | tracked % | load |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="rb-send-") as tmp:
        clip = Path(tmp)
        for i, f in enumerate(frames):
            cv2.imwrite(str(clip / f"{i:06d}.png"), f)
        for _ in range(args.rounds):
            for later in (False, True):
                r = run_once(cfg, clip, args.fps, args.seconds, later, skip=len(frames) + 10)
                print(f"| {'on' if later else 'off'} | {r['frames']:.0f} | {r['dropped']:.0f} "
                      f"| {r['send_p50']:.2f} / {r['send_p99']:.2f} / {r['send_max']:.2f} | {r['frame_cpu_ms']:.3f} "
                      f"| {r['wall_p50']:.2f} / {r['wall_p99']:.2f} | {r['tracked_pct']:.0f} "
                      f"| {os.getloadavg()[0]:.1f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
