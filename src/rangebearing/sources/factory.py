"""Open the frame source a config names: the one place that knows every backend.

Backends are imported only when chosen, so the daemon on a Pi never loads the
synthetic renderer and a laptop never needs picamera2.
"""

from __future__ import annotations

import time

from ..config import SourceConfig
from ..core.types import CameraIntrinsics
from ..errors import SourceError
from .base import FrameSource, Sleep


def open_source(
    cfg: SourceConfig, camera: CameraIntrinsics, sleep: Sleep = time.sleep, in_place: bool = False
) -> FrameSource:
    """Build the source ``cfg.kind`` names, open it and return it.

    ``camera`` sizes the synthetic renderer; the other sources take their size
    from ``cfg``. Opening an already open source is a no-op, so a caller that
    calls ``open()`` again is harmless. The caller owns the source and must
    ``close()`` it. ``sleep`` paces recorded and synthetic frames and spaces
    camera retries; pass ``threading.Event.wait`` so that setting the event
    cuts any wait short (a sleep that returns True ends the wait). ``in_place``
    lets the camera hand over views into its buffers, valid until the next
    ``read()`` (``Frame.borrowed``), and a looping recording its cached frames
    uncopied (read-only): for a caller that is done with each frame before the
    next (the daemon).

    Raises
    ------
    SourceError
        The kind is unknown, or the source cannot be opened
        (CameraError for a missing or busy camera).
    """
    source: FrameSource
    if cfg.kind == "recorded":
        from .recorded import RecordedSource

        source = RecordedSource(cfg.path, fps=cfg.fps, loop=cfg.loop, sleep=sleep, lores=cfg.lores, in_place=in_place)
    elif cfg.kind == "opencv":
        from .opencv_capture import OpenCVSource

        source = OpenCVSource(
            cfg.device, cfg.width_px, cfg.height_px, cfg.fps,
            timeout_s=cfg.timeout_s, retries=cfg.retries,
        )
    elif cfg.kind == "picamera2":
        from .picamera2_source import Picamera2Source

        source = Picamera2Source(cfg, sleep=sleep, in_place=in_place)
    elif cfg.kind == "synthetic":
        from .synthetic import SyntheticSource

        source = SyntheticSource(cfg, camera, sleep=sleep)
    else:
        raise SourceError(f"unknown source kind {cfg.kind!r}")
    source.open()
    return source
