"""Setting up a Pi camera: the controls a config asks for, and how many cameras libcamera sees."""

from __future__ import annotations

from typing import Any, Dict

from ..config import SourceConfig


def camera_controls(cfg: SourceConfig) -> Dict[str, Any]:
    """The libcamera controls for ``cfg``: a fixed frame rate, then ``cfg.controls`` on top.

    ``FrameDurationLimits`` (µs, min and max) is what libcamera takes; newer
    picamera2 also accepts ``FrameRate``, which it turns into the same thing.
    """
    controls: Dict[str, Any] = {}
    if cfg.fps > 0:  # 0 (e.g. --fps 0): the camera's own default
        frame_us = round(1e6 / cfg.fps)
        controls["FrameDurationLimits"] = (frame_us, frame_us)
    user = dict(cfg.controls)
    if "FrameRate" in user:
        controls.pop("FrameDurationLimits", None)
    controls.update(user)
    return controls


def camera_count(picamera2_cls: Any) -> int:
    """How many cameras libcamera sees; a picamera2 that cannot say lets ``Picamera2(n)`` find out (a huge count)."""
    try:
        return len(picamera2_cls.global_camera_info())
    except Exception:  # deliberately broad: the constructor then says what is wrong
        return 1 << 30


def camera_count_text(picamera2_cls: Any) -> str:
    """The camera count for a message ("none" if picamera2 cannot say)."""
    try:
        return str(len(picamera2_cls.global_camera_info()))
    except Exception:  # only for the message: never mask the real error
        return "none"
