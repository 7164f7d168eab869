"""Setting up a Pi camera: the controls a config asks for, and how many cameras libcamera sees."""

from __future__ import annotations

import importlib
import logging
from typing import Any, Dict, Optional

from ..config import SourceConfig
from ..errors import CameraError, CameraLibraryError

_log = logging.getLogger(__name__)
INSTALL_HINT = "apt install python3-picamera2 and create the venv with --system-site-packages"


def optional_module(name: str) -> Any:
    """The module, or None: picamera2 needs libcamera, but a stand-in picamera2 may come without it."""
    try:
        return importlib.import_module(name)
    except ImportError:
        return None


def import_module(name: str) -> Any:
    """The module, or CameraLibraryError with the install hint."""
    try:
        return importlib.import_module(name)
    except ImportError as exc:
        raise CameraLibraryError(f"cannot import {name} ({exc}); {INSTALL_HINT}") from None


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


def video_configuration(cfg: SourceConfig, libcamera: Any) -> Dict[str, Any]:
    """Keyword arguments of ``create_video_configuration`` for ``cfg``: main RGB888 (+ lores YUV420).

    ``libcamera`` (the module, or None where it cannot be imported) gives the
    colour space (SMPTE 170M, set explicitly: picamera2 picks Rec709 from
    1280×720 up) and the flips. Without it picamera2 picks the colour space
    and :func:`~.camera_buffers.granted` reads which; flips then cannot be asked
    for (CameraError).
    """
    size = (cfg.width_px, cfg.height_px)  # a tuple: picamera2 refuses a list ("should be (width, height)")
    kwargs: Dict[str, Any] = {
        "main": {"format": "RGB888", "size": size},
        "lores": {"format": "YUV420", "size": size} if cfg.lores else None,
        "controls": camera_controls(cfg),
        "buffer_count": cfg.buffer_count,
    }
    if libcamera is not None:
        kwargs["colour_space"] = libcamera.ColorSpace.Smpte170m()
        kwargs["transform"] = libcamera.Transform(hflip=cfg.hflip, vflip=cfg.vflip)
    elif cfg.hflip or cfg.vflip:
        raise CameraError(f"camera {cfg.camera_num}: source.hflip/vflip need libcamera.Transform, "
                          "and libcamera cannot be imported")
    return kwargs


def create_configuration(cam: Any, cfg: SourceConfig, libcamera: Any) -> Dict[str, Any]:
    """``cam.create_video_configuration`` for ``cfg``; a picamera2 that takes no ``colour_space`` / ``transform``
    gets the core keywords only (its colour space is read from what it grants; flips then need it: CameraError).
    """
    kwargs = video_configuration(cfg, libcamera)
    create = _config_maker(cam, cfg.camera_num)
    if create is None:  # a stand-in with configure() only: the dict picamera2 would have made, by hand
        return {"use_case": "video", **kwargs, "raw": None, "queue": True}
    while True:
        try:
            config = create(**kwargs)
            break
        except TypeError as exc:  # a keyword this picamera2 does not take: without it (main is never dropped)
            refused = _refused_keyword(exc, kwargs)
            if refused is None:
                raise
        if refused in ("colour_space", "transform"):
            if cfg.hflip or cfg.vflip:
                raise CameraError(f"camera {cfg.camera_num}: source.hflip/vflip need "
                                  "create_video_configuration(transform=)")
            _log.warning("camera %d: the configuration takes no colour_space/transform: the camera's own",
                         cfg.camera_num)
            kwargs = {k: v for k, v in kwargs.items() if k not in ("colour_space", "transform")}
        else:
            _log.warning("camera %d: the configuration takes no %s=: left out", cfg.camera_num, refused)
            kwargs = {k: v for k, v in kwargs.items() if k != refused}
    if "controls" not in kwargs and isinstance(config, dict):  # configure() reads them from the dict
        config = {**config, "controls": {**(config.get("controls") or {}), **camera_controls(cfg)}}
    return config


_DROPPABLE = ("colour_space", "transform", "buffer_count", "controls", "lores")


def _refused_keyword(exc: TypeError, kwargs: Dict[str, Any]) -> Optional[str]:
    """The keyword a TypeError names ("unexpected keyword argument 'buffer_count'"), if it can go; else None.

    A TypeError that names none (a stand-in's own wording) drops the libcamera extras first, if still there.
    """
    text = str(exc)
    named = [k for k in _DROPPABLE if k in kwargs and f"'{k}'" in text]
    if named:
        return named[0]
    return "colour_space" if "colour_space" in kwargs else None


def _config_maker(cam: Any, camera_num: int) -> Any:
    """``create_video_configuration``, else the preview or still one (same keywords), else None."""
    for name in ("create_video_configuration", "create_preview_configuration", "create_still_configuration"):
        create = getattr(cam, name, None)
        if callable(create):
            if name != "create_video_configuration":
                _log.warning("camera %d: no create_video_configuration(): using %s()", camera_num, name)
            return create
    _log.warning("camera %d: no create_*_configuration(): configuring with a dict of our own", camera_num)
    return None


def granted_configuration(cam: Any, asked: Dict[str, Any]) -> Dict[str, Any]:
    """The configuration the camera runs with: ``camera_configuration()``, else per stream, else what was asked.

    Every picamera2 since 0.3 has ``camera_configuration()`` (it returns the
    ``camera_config`` attribute, read next); without them the streams come from
    ``stream_configuration(name)``; without all three, the dict
    passed to ``configure()`` (whose stream dicts the real ``configure`` fills in
    with the granted size, format and stride: it copies the outer dict only).
    """
    asked = as_dict(asked)
    for read in (lambda: cam.camera_configuration(), lambda: cam.camera_config):  # the first returns the second
        try:
            active = as_dict(read())
        except (AttributeError, TypeError, RuntimeError, KeyError):
            continue
        if isinstance(active.get("main"), dict):
            if "colour_space" not in active and "colour_space" in asked:
                return {**active, "colour_space": asked["colour_space"]}
            return active
    streams: Dict[str, Any] = {}
    try:
        for name in ("main", "lores"):
            if asked.get(name) is not None:
                streams[name] = as_dict(cam.stream_configuration(name))
        if isinstance(streams.get("main"), dict) and streams["main"]:
            return {**asked, **streams}
    except (AttributeError, TypeError, RuntimeError, KeyError):
        pass
    return asked


def as_dict(config: Any) -> Dict[str, Any]:
    """A configuration as picamera2's dict: a dict as is, a ``CameraConfiguration`` / ``StreamConfiguration``
    (picamera2 configuration.py) through ``make_dict()``; anything else is an empty dict.
    """
    if isinstance(config, dict):
        return config
    make_dict = getattr(config, "make_dict", None)
    if callable(make_dict):
        made = make_dict()
        return made if isinstance(made, dict) else {}
    return {}
