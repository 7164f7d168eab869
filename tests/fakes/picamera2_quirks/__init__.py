"""A third picamera2 stand-in: the documented API, each corner it may take on its own switched on by name.

Written from picamera2's source (picamera2.py, request.py, job.py at 3e6dff0) and its manual, as a fake
someone else might write: no libcamera module, lockstep frames (one made per capture), and in ``QUIRKS``
the ways such a fake (or an older or newer picamera2) can differ from ours while staying within what the
library documents or has done:

- ``no_wait``: ``capture_request()`` / ``capture_array()`` take no ``wait=`` (picamera2 before 0.3.9).
- ``builtin_timeout``: a stalled capture raises the builtin ``TimeoutError`` (Python ≥ 3.11 futures).
- ``flush_fails``: ``cancel_all_and_flush()`` raises RuntimeError ("Camera not started").
- ``no_metadata``: requests have no ``get_metadata``; ``metadata_none``: it returns None.
- ``none_request``: one ``capture_request`` in ``none_every`` returns None.
- ``lores_unpadded``: lores YUV420 as (H·3/2, W), no stride padding; main rows are padded (64 bytes) anyway.
- ``lores_smaller``: libcamera grants the lores stream at half the size asked.
- ``map_fails``: ``MappedArray.__enter__`` raises RuntimeError("failed to find buffer") (request.py _MappedBuffer).
- ``xbgr``: main granted as XBGR8888 ([R, G, B, 255] bytes).
- ``release_fails``: ``release()`` raises RuntimeError (negative ref_count, request.py 117-118).
- ``make_array_fails``: ``make_array`` raises RuntimeError("Format ... not supported") for the main stream once.
- ``close_fails``: ``stop()`` and ``close()`` raise RuntimeError.
- ``float_timestamp``: ``SensorTimestamp`` is a float; ``no_frame_duration``: no ``FrameDuration``.
- ``tuple_config``: ``camera_configuration()`` returns lists for sizes and a plain string colour space.
- ``flat_main``: the main stream as its (H, stride) rows; ``flat_bytes``: as one run of bytes (``make_buffer``).
- ``open_fails``: the first ``Picamera2()`` raises OSError (ENODEV); ``start_fails``: the first ``start()``
  raises ValueError.
- the main stream granted in another format than RGB888 (libcamera's ``validate()``; request.py
  ``_make_array_shared`` layouts): ``yuv420_main`` (H·3/2, stride), ``nv12_main`` (which ``make_array``
  cannot shape: "Format NV12 not supported", only ``make_buffer`` gives it), ``yuyv_main`` (H, stride/2, 2),
  ``rgb16_main`` (RGB161616: (H, W, 3) uint16), ``mjpeg_main`` (decoded to R, G, B as PIL does),
  ``mjpeg_bytes`` (``make_array`` gives the JPEG bytes, as a fake without PIL would).
- ``make_buffer_fails``: ``make_buffer`` raises too (with ``make_array_fails``: a main stream nothing can read).
- ``config_attr_only``: no ``camera_configuration()`` / ``stream_configuration()``, only the ``camera_config``
  attribute; ``configure()`` deep-copies what it is given (so the asked dict says nothing) and grants XBGR8888.
- ``preview_only``: no ``create_video_configuration`` (``create_preview_configuration`` only);
  ``no_create``: no ``create_*_configuration`` at all (``configure(dict)`` only).
- ``config_objects``: configurations are objects as in picamera2 configuration.py (``CameraConfiguration``:
  attributes and ``make_dict()``, not subscriptable), from ``create_*`` and ``camera_configuration()``.
- ``few_keywords``: ``create_video_configuration`` takes ``main`` and ``lores`` only (TypeError "unexpected
  keyword argument" for the rest, as an early or a hand-written picamera2 would); ``configure()`` still
  reads ``controls`` from the dict.
- ``aligned``: ``configure()`` applies ``align_configuration(optimal=True)`` (VC4: widths down to 32 px,
  YUV420 64, XBGR8888 16; heights even), so the size granted is not the one asked.

``SCENE(sequence) -> (H, W, 3)`` gives the frames in TRUE (R, G, B) order; ``STALLED`` makes captures wait.
"""

from __future__ import annotations

import concurrent.futures
import copy
import os
import threading
from typing import Any, Callable, Dict, List, Optional

import cv2
import numpy as np

QUIRKS: set = set()
NONE_EVERY = 3
STALLED = threading.Event()
OPEN: set = set()
HELD: List[CompletedRequest] = []
INSTANCES: List[Picamera2] = []
FAILED: Dict[str, bool] = {}  # the one-time failures already made


def _default_scene(sequence: int, height: int, width: int) -> np.ndarray:
    rgb = np.zeros((height, width, 3), np.uint8)
    rgb[..., 0] = (sequence * 7) % 256
    rgb[..., 1] = 128
    rgb[..., 2] = 255 - (sequence * 7) % 256
    return rgb


SCENE: Callable[[int, int, int], np.ndarray] = _default_scene


def _from_env() -> None:
    """For a ``rangebearing run`` process: PICAMERA2_QUIRKS="no_wait,release_fails", PICAMERA2_SCENE=<RGB .npy>."""
    global SCENE
    QUIRKS.update(q for q in os.environ.get("PICAMERA2_QUIRKS", "").split(",") if q)
    path = os.environ.get("PICAMERA2_SCENE")
    if path:
        image = np.load(path)
        SCENE = lambda sequence, height, width: image  # noqa: E731


_from_env()


def reset() -> None:
    """Defaults again (a test's teardown), every camera closed."""
    global SCENE, NONE_EVERY
    for cam in list(INSTANCES):
        cam.close()
    QUIRKS.clear()
    FAILED.clear()
    STALLED.clear()
    OPEN.clear()
    HELD.clear()
    INSTANCES.clear()
    SCENE, NONE_EVERY = _default_scene, 3


def _ycbcr_levels(rgb: np.ndarray) -> tuple:
    """SMPTE 170M limited-range Y, Cb, Cr of an RGB image, unrounded (float64, full resolution)."""
    r, g, b = (rgb[..., i].astype(np.float64) for i in range(3))
    y = 16 + (65.481 * r + 128.553 * g + 24.966 * b) / 255
    u = 128 + (-37.797 * r - 74.203 * g + 112.0 * b) / 255
    v = 128 + (112.0 * r - 93.786 * g - 18.214 * b) / 255
    return y, u, v


def _rgb_to_yuv420(rgb: np.ndarray, stride: int) -> np.ndarray:
    """SMPTE 170M limited-range I420, (H·3/2, stride) with the chroma rows stride/2 (picamera2's layout)."""
    h, w = rgb.shape[:2]
    y, u, v = _ycbcr_levels(rgb)
    out = np.zeros((h * 3 // 2, stride), np.uint8)
    out[:h, :w] = np.clip(np.rint(y), 0, 255)
    chroma = out[h:].reshape(2, h // 2, stride // 2)
    for plane, src in zip(chroma, (u, v)):
        half = src.reshape(h // 2, 2, w // 2, 2).mean(axis=(1, 3))
        plane[:, : w // 2] = np.clip(np.rint(half), 0, 255)
    return out


# quirk -> the main format configure() grants
MAIN_GRANTS = {"xbgr": "XBGR8888", "config_attr_only": "XBGR8888", "yuv420_main": "YUV420", "nv12_main": "NV12",
               "yuyv_main": "YUYV", "rgb16_main": "RGB161616", "mjpeg_main": "MJPEG", "mjpeg_bytes": "MJPEG"}
BYTES_PER_PX = {"RGB888": 3, "XBGR8888": 4, "YUV420": 1, "NV12": 1, "YUYV": 2, "RGB161616": 6, "MJPEG": 1}
ALIGN = {"XBGR8888": 16, "RGB161616": 16, "YUV420": 64}  # align_stream on VC4 (picamera2.py 1087-1100), else 32


def _rgb_to_ycbcr(rgb: np.ndarray) -> tuple:
    return tuple(np.clip(np.rint(c), 0, 255).astype(np.uint8) for c in _ycbcr_levels(rgb))


def _main_buffer(rgb: np.ndarray, fmt: str, stride: int) -> np.ndarray:
    """The main stream's bytes as the camera would lay them out (rows of ``stride`` bytes; MJPEG: the file)."""
    h, w = rgb.shape[:2]
    if fmt == "YUV420":
        return _rgb_to_yuv420(rgb, stride)
    if fmt == "MJPEG":
        ok, jpeg = cv2.imencode(".jpg", np.ascontiguousarray(rgb[..., ::-1]), [cv2.IMWRITE_JPEG_QUALITY, 95])
        assert ok
        return jpeg.reshape(-1)
    y, u, v = _rgb_to_ycbcr(rgb)
    if fmt == "NV12":
        out = np.zeros((h * 3 // 2, stride), np.uint8)
        out[:h, :w] = y
        half = [c.reshape(h // 2, 2, w // 2, 2).mean(axis=(1, 3)).round().astype(np.uint8) for c in (u, v)]
        out[h:, :w] = np.stack(half, axis=2).reshape(h // 2, w)
        return out
    if fmt == "YUYV":
        pixels = np.stack([y[:, 0::2], u[:, 0::2], y[:, 1::2], v[:, 0::2]], axis=2).reshape(h, 2 * w)
    elif fmt == "RGB161616":  # [B, G, R] words as RGB888's bytes, little-endian, full 16-bit scale
        pixels = (rgb[..., ::-1].astype("<u2") * 257).reshape(h, -1).view(np.uint8)
    elif fmt == "XBGR8888":  # [R, G, B, X] bytes
        pixels = np.concatenate([rgb, np.full((h, w, 1), 255, np.uint8)], axis=2).reshape(h, -1)
    else:  # RGB888: [B, G, R] bytes
        pixels = rgb[..., ::-1].reshape(h, -1)
    flat = np.zeros((h, stride), np.uint8)
    flat[:, : pixels.shape[1]] = pixels
    return flat


class Configuration:
    """picamera2 configuration.py's object form of a configuration dict: attributes and ``make_dict()``."""

    _STREAMS = ("main", "lores", "raw", "sensor")

    def __init__(self, d: Dict[str, Any]) -> None:
        self.__dict__["_d"] = {k: Configuration(v) if k in self._STREAMS and isinstance(v, dict) else v
                               for k, v in d.items()}

    def __getattr__(self, name: str) -> Any:
        try:
            return self.__dict__["_d"][name]
        except KeyError:
            raise AttributeError(name) from None

    def make_dict(self) -> Dict[str, Any]:
        return {k: v.make_dict() if isinstance(v, Configuration) else v for k, v in self.__dict__["_d"].items()}


class Job:
    """What a false ``wait`` returns (job.py): ``get_result(timeout)``."""

    def __init__(self, result: Any) -> None:
        self._result = result

    def get_result(self, timeout: Optional[float] = None) -> Any:
        return self._result


class CompletedRequest:
    def __init__(self, cam: Picamera2, sequence: int) -> None:
        self.picam2 = cam
        self.config = cam.camera_config
        self.ref_count = 1
        self.sequence = sequence
        self.buffers: Dict[str, np.ndarray] = {}
        main = cam.camera_config["main"]
        w, h = main["size"]
        rgb = np.ascontiguousarray(SCENE(sequence, *reversed(cam.asked_main))[:h, :w])
        self.buffers["main"] = _main_buffer(rgb, main["format"], main["stride"])
        lores = cam.camera_config.get("lores")
        if lores is not None:
            lw, lh = lores["size"]
            small = rgb if (lw, lh) == (w, h) else rgb[::h // lh, ::w // lw][:lh, :lw]
            self.buffers["lores"] = _rgb_to_yuv420(np.ascontiguousarray(small), lores["stride"])

    def _shaped(self, name: str) -> np.ndarray:
        cfg = self.config[name]
        buf = self.buffers[name]
        w, h = cfg["size"]
        fmt = cfg["format"]
        if name == "main" and "flat_main" in QUIRKS:
            return buf
        if name == "main" and "flat_bytes" in QUIRKS:
            return buf.reshape(-1)
        if fmt == "RGB888":
            return buf[:, : w * 3].reshape(h, w, 3)
        if fmt == "XBGR8888":
            return buf[:, : w * 4].reshape(h, w, 4)
        if fmt == "RGB161616":
            return buf[:, : w * 6].view(np.uint16).reshape(h, w, 3)
        if fmt == "YUYV":
            return buf.reshape(h, buf.shape[1] // 2, 2)
        if fmt == "MJPEG":
            if "mjpeg_bytes" in QUIRKS:
                return buf
            return cv2.imdecode(buf, cv2.IMREAD_COLOR)[..., ::-1]  # PIL's R, G, B
        if fmt == "NV12":
            raise RuntimeError("Format NV12 not supported")
        return buf  # YUV420: (H·3/2, stride), padding kept

    def make_buffer(self, name: str) -> np.ndarray:
        if "make_buffer_fails" in QUIRKS:
            raise RuntimeError("failed to find buffer")
        return self.buffers[name].reshape(-1).copy()

    def make_array(self, name: str) -> np.ndarray:
        if self.ref_count <= 0:
            raise RuntimeError("CompletedRequest: request already released")
        if "make_array_fails" in QUIRKS and name == "main" and self.sequence == 1:
            raise RuntimeError("Format XYZ not supported")
        return self._shaped(name).copy()

    @property
    def get_metadata(self) -> Callable[[], Optional[Dict[str, Any]]]:
        if "no_metadata" in QUIRKS:  # a request with no get_metadata at all
            raise AttributeError("get_metadata")
        return self._metadata

    def _metadata(self) -> Optional[Dict[str, Any]]:
        if "metadata_none" in QUIRKS:
            return None
        ts = 1_000_000_000 + self.sequence * self.picam2.frame_us * 1000
        meta: Dict[str, Any] = {"SensorTimestamp": float(ts) if "float_timestamp" in QUIRKS else ts}
        if "no_frame_duration" not in QUIRKS:
            meta["FrameDuration"] = self.picam2.frame_us
        return meta

    def release(self) -> None:
        self.ref_count -= 1
        if self in HELD:
            HELD.remove(self)
        if self.ref_count < 0 or "release_fails" in QUIRKS:
            raise RuntimeError("CompletedRequest: lock now has negative ref_count")
        self.buffers = {k: np.full_like(v, 0xEE) for k, v in self.buffers.items()}  # recycled


class MappedArray:
    def __init__(self, request: CompletedRequest, stream: str, reshape: bool = True, write: bool = True) -> None:
        self._request, self._stream = request, stream
        self.array: Optional[np.ndarray] = None

    def __enter__(self) -> MappedArray:
        if "map_fails" in QUIRKS:
            raise RuntimeError("failed to find buffer")
        self.array = self._request._shaped(self._stream)
        return self

    def __exit__(self, *exc: Any) -> None:
        self.array = None


class Picamera2:
    def __init__(self, camera_num: int = 0, verbose_console: Any = None, tuning: Any = None,
                 allocator: Any = None) -> None:
        if camera_num != 0:
            raise IndexError("list index out of range")
        if "open_fails" in QUIRKS and not FAILED.get("open"):
            FAILED["open"] = True
            raise OSError(19, "No such device")
        if camera_num in OPEN:
            raise RuntimeError("Camera __init__ sequence did not complete.")
        OPEN.add(camera_num)
        self.camera_num = camera_num
        self.camera_config: Dict[str, Any] = {}
        self.started = False
        self.closed = False
        self.sequence = 0
        self.frame_us = 33333
        self.asked_main = (640, 480)
        INSTANCES.append(self)

    def __getattribute__(self, name: str) -> Any:
        gone = {"config_attr_only": ("camera_configuration", "stream_configuration"),
                "preview_only": ("create_video_configuration",),
                "no_create": ("create_video_configuration", "create_preview_configuration",
                              "create_still_configuration")}
        if any(name in names for quirk, names in gone.items() if quirk in QUIRKS):
            raise AttributeError(name)  # hasattr() says False, as for a picamera2 without the method
        return object.__getattribute__(self, name)

    @staticmethod
    def global_camera_info() -> List[Dict[str, Any]]:
        return [{"Model": "imx219", "Location": 2, "Rotation": 0, "Id": "/base/imx219@10", "Num": 0}]

    def create_video_configuration(self, *args: Any, **kw: Any) -> Any:
        if "few_keywords" in QUIRKS:
            for key in kw:
                if key not in ("main", "lores"):
                    raise TypeError(f"create_video_configuration() got an unexpected keyword argument '{key}'")
        config = self._video_configuration(*args, **kw)
        return Configuration(config) if "config_objects" in QUIRKS else config

    def _video_configuration(self, main: Optional[dict] = None, lores: Optional[dict] = None,
                                   raw: Any = None, transform: Any = None, colour_space: Any = None,
                                   buffer_count: int = 6, controls: Optional[dict] = None, **kw: Any) -> dict:
        for key in kw:
            if key not in ("display", "encode", "queue", "sensor", "use_case"):
                raise TypeError(f"create_video_configuration() got an unexpected keyword argument {key!r}")
        return {"use_case": "video", "transform": transform, "colour_space": colour_space,
                "buffer_count": buffer_count, "queue": True, "main": dict(main or {"format": "XBGR8888",
                                                                                   "size": (1280, 720)}),
                "lores": None if lores is None else dict(lores), "raw": None,
                "controls": dict(controls or {}), "sensor": {}, "display": "main", "encode": "main"}

    def create_preview_configuration(self, main: Optional[dict] = None, lores: Optional[dict] = None,
                                     **kw: Any) -> dict:
        video = object.__getattribute__(self, "create_video_configuration")  # there even with preview_only
        return {**video(main or {"format": "XBGR8888", "size": (640, 480)}, lores, **kw), "use_case": "preview"}

    create_still_configuration = create_preview_configuration

    def configure(self, config: Any = None) -> None:
        if self.started:
            raise RuntimeError("Camera must be stopped before configuring")
        if isinstance(config, Configuration):
            config = config.make_dict()
        config = copy.deepcopy(config) if "config_attr_only" in QUIRKS else dict(config)
        main = config["main"]
        w, h = (int(v) for v in main["size"])
        self.asked_main = (w, h)
        fmt = next((f for q, f in MAIN_GRANTS.items() if q in QUIRKS), main["format"])
        if "aligned" in QUIRKS:
            w, h = w - w % ALIGN.get(fmt, 32), h - h % 2
        main.update(format=fmt, size=(w, h), stride=((w * BYTES_PER_PX[fmt] + 63) // 64) * 64)
        main["framesize"] = main["stride"] * h * 3 // 2 if fmt in ("YUV420", "NV12") else main["stride"] * h
        lores = config.get("lores")
        if lores is not None:
            lw, lh = (int(v) for v in lores["size"])
            if "aligned" in QUIRKS:
                lw, lh = lw - lw % 64, lh - lh % 2
            if "lores_smaller" in QUIRKS:
                lw, lh = lw // 2, lh // 2
            stride = lw if "lores_unpadded" in QUIRKS else ((lw + 63) // 64) * 64
            lores.update(size=(lw, lh), stride=stride, framesize=stride * lh * 3 // 2)
        if config.get("colour_space") is None:
            config["colour_space"] = "Smpte170m" if w < 1280 else "Rec709"
        if "FrameDurationLimits" in config.get("controls", {}):
            self.frame_us = int(config["controls"]["FrameDurationLimits"][0])
        if "tuple_config" in QUIRKS:
            main["size"] = list(main["size"])
            config["colour_space"] = str(config["colour_space"])
        self.camera_config = config

    def camera_configuration(self) -> Any:
        return Configuration(self.camera_config) if "config_objects" in QUIRKS else self.camera_config

    def stream_configuration(self, name: str = "main") -> Any:
        stream = self.camera_config[name]
        return Configuration(stream) if "config_objects" in QUIRKS else stream

    def start(self, config: Any = None, show_preview: bool = False) -> None:
        if not self.camera_config:
            raise RuntimeError("Camera has not been configured")
        if "start_fails" in QUIRKS and not FAILED.get("start"):
            FAILED["start"] = True
            raise ValueError("bad control value")
        self.started = True

    def _next(self, timeout: Optional[float]) -> CompletedRequest:
        if not self.started:
            raise RuntimeError("Camera not started")
        if STALLED.is_set():
            if timeout is None:
                raise RuntimeError("a capture without wait= would block for ever: this fake refuses")
            STALLED.wait(0)  # no frame comes
            if "builtin_timeout" in QUIRKS:
                raise TimeoutError()
            raise concurrent.futures.TimeoutError()
        self.sequence += 1
        request = CompletedRequest(self, self.sequence)
        HELD.append(request)
        return request

    def capture_request(self, *args: Any, **kwargs: Any) -> Any:
        if "no_wait" in QUIRKS and (args or kwargs):
            raise TypeError("capture_request() takes 1 positional argument but more were given")
        wait = kwargs.get("wait", args[0] if args else None)
        if wait is not None and not wait:
            return Job(self._next(None))
        if "none_request" in QUIRKS and (self.sequence + 1) % NONE_EVERY == 0:
            self.sequence += 1
            return None
        return self._next(wait if "no_wait" not in QUIRKS else 1.0)

    def capture_array(self, name: str = "main", *args: Any, **kwargs: Any) -> np.ndarray:
        if "no_wait" in QUIRKS and (args or kwargs):
            raise TypeError("capture_array() takes 2 positional arguments but more were given")
        request = self._next(kwargs.get("wait", 1.0))
        try:
            return request.make_array(name)
        finally:
            request.release()

    def cancel_all_and_flush(self) -> None:
        if "flush_fails" in QUIRKS:
            raise RuntimeError("Camera not started")

    def set_controls(self, controls: Dict[str, Any]) -> None:
        self.camera_config.setdefault("controls", {}).update(controls)

    def stop(self) -> None:
        if "close_fails" in QUIRKS:
            raise RuntimeError("stop failed")
        self.started = False

    def close(self) -> None:
        if self.closed:
            return
        self.closed = True
        self.started = False
        OPEN.discard(self.camera_num)
        if "close_fails" in QUIRKS:
            raise RuntimeError("close failed")
