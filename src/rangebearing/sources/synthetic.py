"""Synthetic frames: a landmark moving on a known path, rendered at ``cfg.fps``.

Paced like a camera (see :class:`~.pacing.Pacer`), so a slow consumer drops
frames just as it would on the robot; :meth:`SyntheticSource.truth` gives the
exact pose behind every frame index.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Callable, Optional, Tuple

import numpy as np

from ..config import SourceConfig
from ..core.types import CameraIntrinsics
from ..errors import FrameError, SourceError
from ..synth.render import render
from ..synth.scene import LandmarkPose, Scene
from .base import Frame, with_lores
from .pacing import Pacer

Path = Callable[[float], Tuple[LandmarkPose, ...]]


def figure_eight(t_s: float) -> Tuple[LandmarkPose, ...]:
    """The default path: one landmark, range 0.3–1.2 m over 10 s, bearing ±0.35 rad over 7 s."""
    range_m = 0.75 + 0.45 * math.sin(2.0 * math.pi * t_s / 10.0)
    bearing_rad = 0.35 * math.sin(2.0 * math.pi * t_s / 7.0)
    return (LandmarkPose(range_m, bearing_rad),)


class SyntheticSource:
    """Rendered frames of ``scene`` with its landmarks placed by ``path(t_s)``.

    The camera is ``camera`` scaled to ``cfg.width_px × cfg.height_px``; frame
    *i* shows the scene at ``t_s = i / cfg.fps``; with ``cfg.fps`` 0 frames
    come as fast as they render, timed as if at 30 fps. ``frames`` ends the stream
    after that many frames (None: never). Noise, if the scene's imaging has
    any, is drawn from ``numpy.random.default_rng(seed)``.
    """

    may_block = False  # reads wait only on ``sleep`` (a stop ends them): no reader thread needed

    def __init__(
        self,
        cfg: SourceConfig,
        camera: CameraIntrinsics,
        *,
        path: Path = figure_eight,
        scene: Optional[Scene] = None,
        frames: Optional[int] = None,
        seed: int = 0,
        clock: Callable[[], int] = time.monotonic_ns,
        sleep: Callable[[float], object] = time.sleep,
    ) -> None:
        try:
            camera = camera.for_frame(cfg.width_px, cfg.height_px)
        except FrameError as exc:
            raise SourceError(f"synthetic source: {exc}") from None
        self._scene = dataclasses.replace(scene or Scene(), camera=camera)
        self._path = path
        self._fps = cfg.fps if cfg.fps > 0 else 30.0
        self._lores = cfg.lores  # the YUV420 stream a Pi camera adds beside each frame
        self._frames = frames
        self._seed = seed
        self._clock = clock
        self._pacer = Pacer(cfg.fps, clock, sleep) if cfg.fps > 0 else None
        self._rng: Optional[np.random.Generator] = None
        self._next = 0
        self._dropped = 0

    @property
    def dropped(self) -> int:
        return self._dropped

    def truth(self, index: int) -> Tuple[LandmarkPose, ...]:
        """The exact landmark poses in frame ``index``."""
        return self._path(index / self._fps)

    def open(self) -> None:
        if self._rng is not None:
            return
        self._rng = np.random.default_rng(self._seed)
        if self._pacer is not None:
            self._pacer.start()
        self._next = 0
        self._dropped = 0

    def read(self) -> Optional[Frame]:
        """The newest due frame, rendered; None after ``frames`` frames."""
        if self._rng is None:
            raise SourceError("synthetic source is not open")
        last = None if self._frames is None else self._frames - 1
        if last is not None and self._next > last:
            return None
        i = self._next
        if self._pacer is not None:
            i = self._pacer.next_index(i, last)
            self._dropped += i - self._next
        self._next = i + 1
        scene = dataclasses.replace(self._scene, landmarks=self.truth(i))
        image = render(scene, self._rng)
        t_ns = self._pacer.capture_ns(i) if self._pacer is not None else self._clock()
        frame = Frame(image=image, t_mono_ns=t_ns, index=i, name=str(i))
        return with_lores(frame) if self._lores else frame

    def close(self) -> None:
        self._rng = None
