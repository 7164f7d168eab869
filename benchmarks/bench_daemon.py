"""Can the daemon keep up? The real capture loop on a paced recording, publishing over loopback UDP."""

from __future__ import annotations

import dataclasses
import socket
import tempfile
import threading
import time
from pathlib import Path
from typing import List, Optional, Sequence

import cv2
import numpy as np

from rangebearing import Config
from rangebearing._compat import frozen
from rangebearing.config import PublishConfig, SourceConfig
from rangebearing.daemon.loop import Daemon
from rangebearing.daemon.sdnotify import Notifier
from rangebearing.net.publisher import UdpPublisher
from rangebearing.sources.base import Frame, FrameSource
from rangebearing.sources.factory import open_source

END = b"END"  # not JSON, so never a reading


@frozen
class DaemonFigures:
    """The keep-up run's outcome (latency is capture to send, from ``Daemon.summary()``)."""

    fps_asked: float
    duration_s: float
    frames_expected: int
    frames: int
    dropped: int
    bad_frames: int
    achieved_fps: float
    latency_ms_p50: float
    latency_ms_p99: float
    stage_ms: str
    received: int
    exit_code: int


class FirstFrames:
    """A frame source that ends after frame index ``limit - 1`` (the looped recording would not end)."""

    def __init__(self, inner: FrameSource, limit: int) -> None:
        self._inner = inner
        self._limit = limit

    def open(self) -> None:
        self._inner.open()

    def read(self) -> Optional[Frame]:
        frame = self._inner.read()
        return None if frame is None or frame.index >= self._limit else frame

    def close(self) -> None:
        self._inner.close()

    @property
    def dropped(self) -> int:
        return self._inner.dropped


def _drain(sock: socket.socket, got: List[int]) -> None:
    while True:
        try:
            data = sock.recv(65536)
        except OSError:  # timed out: the sender is gone
            return
        if data == END:
            return
        got[0] += 1


def daemon_check(cfg: Config, frames: Sequence[np.ndarray], fps: float, duration_s: float) -> DaemonFigures:
    """Run :class:`~rangebearing.daemon.Daemon` in-process on ``frames`` (PNG, looped) paced at ``fps``.

    ``cfg`` carries the camera; tracking is whatever ``cfg.detection.tracking`` says (on by default).
    Readings go to a socket bound on 127.0.0.1, which counts them.
    """
    limit = round(fps * duration_s)
    with tempfile.TemporaryDirectory(prefix="rb-bench-") as tmp, socket.socket(
        socket.AF_INET, socket.SOCK_DGRAM
    ) as rx:
        for i, frame in enumerate(frames):
            cv2.imwrite(str(Path(tmp) / f"{i:06d}.png"), frame)
        rx.bind(("127.0.0.1", 0))
        rx.settimeout(duration_s + 30.0)
        port = rx.getsockname()[1]
        got = [0]
        drainer = threading.Thread(target=_drain, args=(rx, got), daemon=True)
        drainer.start()
        run_cfg = dataclasses.replace(
            cfg,
            source=SourceConfig(kind="recorded", path=tmp, fps=fps, loop=True),
            publish=PublishConfig(unicast=(("127.0.0.1", port),)),
        )

        def open_src(c: Config, sleep) -> FrameSource:
            return FirstFrames(open_source(c.source, c.camera, sleep=sleep), limit)

        daemon = Daemon(run_cfg, open_src, lambda c: UdpPublisher(c.publish), Notifier(environ={}))
        t0 = time.perf_counter()
        code = daemon.run()
        wall = time.perf_counter() - t0
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as tx:
            tx.sendto(END, ("127.0.0.1", port))
        drainer.join(timeout=10.0)
    s = daemon.summary()
    return DaemonFigures(
        fps_asked=fps,
        duration_s=duration_s,
        frames_expected=limit,
        frames=s.frames,
        dropped=s.dropped,
        bad_frames=s.bad_frames,
        achieved_fps=s.frames / wall if wall > 0 else 0.0,
        latency_ms_p50=s.latency_ms_p50,
        latency_ms_p99=s.latency_ms_p99,
        stage_ms=", ".join(f"{k} {v:.2f}" for k, v in s.stage_ms.items()),
        received=got[0],
        exit_code=code,
    )
