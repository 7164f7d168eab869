"""A capture loop in a thread for view tests: recorded frames → Pipeline → ViewHub, as the daemon does."""

from __future__ import annotations

import threading
import time
from pathlib import Path
from typing import List, Optional

import cv2
import numpy as np

from rangebearing.config import Config
from rangebearing.core.pipeline import Pipeline
from rangebearing.view import ViewHub


class Feeder:
    """Loop over the images of ``clip`` at ``fps``, applying the hub's thresholds between frames."""

    def __init__(self, hub: ViewHub, clip: Path, cfg: Optional[Config] = None, fps: float = 20.0) -> None:
        self.hub, self.cfg, self.fps = hub, cfg or Config(), fps
        self.files = sorted(p for p in Path(clip).iterdir() if p.suffix in (".jpg", ".png"))
        self.images: List[np.ndarray] = [cv2.imread(str(p)) for p in self.files]
        self.pipe = Pipeline(self.cfg.pipeline)
        self.frames = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        i = 0
        while not self._stop.is_set():
            new = self.hub.take_thresholds()
            if new is not None:
                import dataclasses

                self.cfg = dataclasses.replace(self.cfg, detection=new.apply(self.cfg.detection))
                self.pipe = Pipeline(self.cfg.pipeline)
            k = i % len(self.images)
            result = self.pipe.process(self.images[k])
            now = time.monotonic_ns()
            if self.hub.wants(now):
                status = {"fps": self.fps, "frames": self.frames, "dropped": 0, "bad_frames": 0}
                self.hub.offer(now, self.images[k], self.files[k].name, result, self.cfg.detection, status)
            self.frames += 1
            i += 1
            self._stop.wait(1.0 / self.fps)

    def __enter__(self) -> Feeder:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join(5.0)
