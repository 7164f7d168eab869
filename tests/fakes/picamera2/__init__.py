"""A faithful fake of picamera2 for tests: same calls, same quirks, no camera.

Mirrors raspberrypi/picamera2 (picamera2.py, request.py, job.py):

* ``Picamera2(n)`` raises IndexError for a camera that is not there and
  RuntimeError("Camera __init__ sequence did not complete.") for one that is
  already open (busy).
* ``capture_request()`` queues a job whose Future is completed by the next
  frame. Without ``wait=`` it blocks forever; with ``wait=t`` it raises
  ``concurrent.futures.TimeoutError`` and the job STAYS queued, so it eats the
  next frame (and leaks its request) unless ``cancel_all_and_flush()`` is
  called. ``stop()`` queues behind such a job and hangs. As
  ``dispatch_functions`` does, a false ``wait`` (``False``, but also ``0``)
  and ``wait=None`` with a ``signal_function`` return the Job, not a request;
  ``job.get_result(timeout)`` (or ``cam.wait(job, timeout)``) gives its result.
  ``capture_array(name)`` and ``capture_metadata()`` are jobs too: the request
  is released inside (``capture_array_``), the array a contiguous copy.
* ``configure()`` checks the config as ``check_camera_config`` does (the five
  keys; each stream a dict with a str format and an even (w, h) TUPLE, else
  RuntimeError) and, copying only the outer dict, writes ``stride`` and
  ``framesize`` into the caller's own stream dicts; ``stream_configuration(name)``
  is ``camera_config[name]``; ``align_configuration`` rounds as on VC4.
* ``"RGB888"`` arrays are [B, G, R] per pixel, ``"BGR888"`` [R, G, B],
  ``"XBGR8888"`` [R, G, B, 255], ``"XRGB8888"`` [B, G, R, 255].
* Requests are reference counted and hold one of ``buffer_count`` buffers;
  when all are held, no frame can complete (the camera stalls). A released
  request's buffers go back to the camera, which writes the next frames into
  them: the fake fills them with 0xEE, so a view kept past ``release()`` shows it.
* ``lores`` (picamera2.py ``create_video_configuration``): a second stream,
  defaults ``{"format": "YUV420", "size": main size, "preserve_ar": False}``,
  no larger than main and YUV only (the Pi 4 ISP, VC4). Its buffer is I420:
  Y (H rows), then U and V (H/2 rows of stride/2 bytes each), the stride
  rounded up to 64 bytes (the padding holds junk, 77). ``MappedArray(request,
  "lores")`` gives it as a (H·3/2, stride) array, as ``_make_array_shared``
  does; the content is the main stream's scaled to the lores size, encoded
  as SMPTE 170M (libcamera's default colour space for video below 1280×720):
  Y as OpenCV's ``COLOR_BGR2YUV_I420``, U and V from each 2×2 block's mean.
* ``MappedArray(request, stream)`` maps the buffer in place (no copy, unlike
  ``make_array``); mapping a released request fails. The main stream's rows
  are ``stride`` bytes, rounded up to 64 as the ISP does: ``MappedArray``
  gives (H, W, C) with the padding sliced off (a view that is not
  C-contiguous when rows are padded), as ``_make_array_shared`` does.
* ``configure()`` fills each stream's ``stride`` and ``framesize``; where the
  camera cannot give what was asked (libcamera's "Adjusted"), the test sets
  ``WORLD.adjusted``, e.g. ``{"main": {"format": "XBGR8888"}, "colour_space":
  libcamera.ColorSpace.Rec709()}``, and ``camera_configuration()`` says what
  was granted, as picamera2 does after ``validate()``.

* ``set_controls()`` takes effect ``WORLD.control_latency_frames`` frames
  later (libcamera applies controls a few frames on); ``ExposureTime`` or
  ``AnalogueGain`` turn auto exposure off, ``ColourGains`` turns auto white
  balance off, as the Pi IPA does. Every request's metadata reports
  ``ExposureTime``, ``AnalogueGain``, ``DigitalGain``, ``ColourGains``,
  ``ColourTemperature``, ``Lux``, ``AeLocked`` and ``ScalerCrop`` (picamera2's
  ``examples/controls.py`` locks AE/AWB by copying the first three back).

Frames are produced synchronously, one per pending job, from ``WORLD.producer``
(RGB content, as auto exposure and white balance would deliver it). With AE
off, pixels scale by (exposure × gain) / (what AE would have chosen); with AWB
off, red and blue scale by the set gain over the automatic one. ``WORLD`` also
stalls the sensor, skips frames (timestamp gaps), pads rows like old ``make_array`` did and makes ``stop()`` hang.
"""

from __future__ import annotations

import threading
import time
from concurrent.futures import CancelledError, Future, TimeoutError
from typing import Any, Callable, Dict, List, Optional

import cv2
import libcamera
import numpy as np

__all__ = ["WORLD", "CancelledError", "CompletedRequest", "MappedArray", "Picamera2", "TimeoutError", "shutdown"]

_KNOWN_CONTROLS = {
    "AeEnable", "ExposureTime", "AnalogueGain", "AwbEnable", "AwbMode", "ColourGains",
    "FrameDurationLimits", "NoiseReductionMode", "Brightness", "Contrast", "Saturation",
    "Sharpness", "ScalerCrop",
}
_CBCR = np.array([[0.439, -0.291, -0.148, 128.0], [-0.071, -0.368, 0.439, 128.0]])  # BGR → U, V (SMPTE 170M)
_BYTES_PER_PIXEL = {"RGB888": 3, "BGR888": 3, "XBGR8888": 4, "XRGB8888": 4}


def _grey_producer(seq: int, height: int, width: int) -> np.ndarray:
    return np.full((height, width, 3), seq % 256, dtype=np.uint8)


class World:
    """The fake camera hardware and the test's handles on it."""

    def __init__(self) -> None:
        self.lock = threading.RLock()
        self.num_cameras = 1
        self.producer: Callable[[int, int, int], np.ndarray] = _grey_producer
        self.frame_period_ns: Optional[int] = None  # None: the configured FrameDurationLimits
        self.sensor_clock_offset_ns = 0  # add e.g. suspend time to mimic CLOCK_BOOTTIME
        self.padded_width_px = 0  # extra junk columns make_array returns (old picamera2)
        self.stalled = False
        self.hang_stop = False
        self.release = threading.Event()  # set at teardown: un-hangs anything blocked
        self.open_cameras: set = set()
        self.instances: List[Picamera2] = []
        self.capture_waits: List[Any] = []
        self.outstanding: List[CompletedRequest] = []
        self.skip_next = 0
        # what the AE/AWB algorithms settle on; ``auto_drift(seq)`` scales the exposure they pick
        self.auto_exposure_us = 12000
        self.auto_gain = 2.0
        self.auto_colour_gains = (1.9, 1.6)
        self.auto_drift: Callable[[int], float] = lambda seq: 1.0
        self.control_latency_frames = 2
        self.pixel_array = (3280, 2464)  # imx219
        self.set_controls_calls: List[Dict[str, Any]] = []
        self.adjusted: Dict[str, Any] = {}  # what libcamera grants instead of what was asked (see configure)

    def set_stalled(self, stalled: bool) -> None:
        """Stall or resume the sensor; resuming completes jobs that are still queued."""
        with self.lock:
            self.stalled = stalled
            for cam in self.instances:
                cam._pump()

    def skip(self, frames: int) -> None:
        """Lose ``frames`` frames before the next one (a gap in SensorTimestamp)."""
        with self.lock:
            self.skip_next += frames


WORLD = World()


def shutdown() -> None:
    """Test teardown: cancel queued jobs and un-hang any blocked stop()."""
    WORLD.release.set()
    with WORLD.lock:
        for cam in WORLD.instances:
            for job in cam._jobs:
                job.cancel()


class CompletedRequest:
    """A frame's buffers and metadata; must be released exactly once."""

    def __init__(self, picam2: Picamera2, image: np.ndarray, metadata: Dict[str, Any],
                 lores: Optional[np.ndarray] = None) -> None:
        self.picam2 = picam2
        self.ref_count = 1
        self._buffers: Optional[Dict[str, np.ndarray]] = {"main": image}
        if lores is not None:
            self._buffers["lores"] = lores
        self._metadata = metadata
        self.config = dict(picam2.camera_config)

    def acquire(self) -> None:
        with WORLD.lock:
            if self.ref_count == 0:
                raise RuntimeError("CompletedRequest: acquiring lock with ref_count 0")
            self.ref_count += 1

    def release(self) -> None:
        with WORLD.lock:
            self.ref_count -= 1
            if self.ref_count < 0:
                raise RuntimeError("CompletedRequest: lock now has negative ref_count")
            if self.ref_count == 0:
                for buf in (self._buffers or {}).values():
                    buf.fill(0xEE)  # back to the camera, which writes the next frames into it
                self._buffers = None
                if self in WORLD.outstanding:
                    WORLD.outstanding.remove(self)
                self.picam2._pump()

    def _shared(self, name: str) -> np.ndarray:
        """The stream's buffer as picamera2's ``_make_array_shared`` shapes it: no copy."""
        if self.config.get(name) is None:
            raise RuntimeError(f"Stream {name!r} is not defined")
        if self._buffers is None:
            raise RuntimeError("failed to find buffer")  # released: the camera owns it again
        buf = self._buffers[name]
        if name == "main":  # (H, stride) bytes: slice the padding off and shape the pixels, no copy
            (w, h), fmt = self.config["main"]["size"], self.config["main"]["format"]
            c = _BYTES_PER_PIXEL[fmt]
            return buf[:, : w * c].reshape(h, w, c)
        return buf  # YUV420: (H·3/2, stride), padding left in, as picamera2 does

    def make_array(self, name: str) -> np.ndarray:
        """A contiguous copy; main gets ``WORLD.padded_width_px`` junk columns, as old picamera2 did."""
        array = np.ascontiguousarray(self._shared(name)).copy()
        if name == "main" and WORLD.padded_width_px:
            pad = np.full((array.shape[0], WORLD.padded_width_px, array.shape[2]), 77, dtype=np.uint8)
            array = np.concatenate([array, pad], axis=1)
        return array

    def get_metadata(self) -> Dict[str, Any]:
        return dict(self._metadata)


class MappedArray:
    """``with MappedArray(request, "lores") as m: m.array`` – the buffer in place, valid inside the block."""

    def __init__(self, request: CompletedRequest, stream: str, reshape: bool = True, write: bool = True) -> None:
        self._request = request
        self._stream = stream
        self._array: Optional[np.ndarray] = None

    def __enter__(self) -> MappedArray:
        self._array = self._request._shared(self._stream)
        return self

    def __exit__(self, *exc: Any) -> None:
        self._array = None

    @property
    def array(self) -> Optional[np.ndarray]:
        return self._array


class _Job:
    """job.py's Job: a Future completed by the frame that runs it; ``finish`` turns the request into the result."""

    def __init__(self, finish: Optional[Callable[[CompletedRequest], Any]] = None) -> None:
        self.future: Future = Future()
        self.future.set_running_or_notify_cancel()
        self._future = self.future  # the real attribute's name
        self.finish = finish  # None: the request itself (capture_request), the caller must release it

    def get_result(self, timeout: Optional[float] = None) -> Any:
        """Blocks (None: forever) for the result; concurrent.futures.TimeoutError past ``timeout``."""
        return self.future.result(timeout=timeout)

    def cancel(self) -> None:
        if not self.future.done():
            self.future.set_exception(CancelledError())


class Picamera2:
    """The fake camera: see the module docstring for the behaviour it copies."""

    def __init__(
        self, camera_num: int = 0, verbose_console: Any = None, tuning: Any = None, allocator: Any = None
    ) -> None:
        with WORLD.lock:
            if not 0 <= camera_num < WORLD.num_cameras:
                raise IndexError("list index out of range")  # global_camera_info()[camera_num]
            if camera_num in WORLD.open_cameras:
                raise RuntimeError("Camera __init__ sequence did not complete.")
            WORLD.open_cameras.add(camera_num)
            WORLD.instances.append(self)
        self.camera_idx = camera_num
        self.is_open = True
        self.started = False
        self.camera_config: Optional[Dict[str, Any]] = None
        self._jobs: List[_Job] = []
        self._seq = 0
        self._t0_ns = 0
        self.stop_calls = 0
        self._pending: List[Any] = []  # (sequence number it applies from, controls)
        self._applied: Dict[str, Any] = {}

    @staticmethod
    def global_camera_info() -> List[Dict[str, Any]]:
        return [{"Model": "imx219", "Id": f"/base/fake/imx219@{i}", "Num": i}
                for i in range(WORLD.num_cameras)]

    def __enter__(self) -> Picamera2:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def create_video_configuration(self, main: Optional[Dict[str, Any]] = None, lores: Any = None,
                                   raw: Any = None, transform: Any = None, colour_space: Any = None,
                                   buffer_count: int = 6, controls: Optional[Dict[str, Any]] = None,
                                   display: Optional[str] = "main", encode: Optional[str] = "main",
                                   queue: bool = True, sensor: Any = None,
                                   use_case: str = "video") -> Dict[str, Any]:
        if not self.is_open:
            raise RuntimeError("Camera not opened")
        stream = {"format": "XBGR8888", "size": (1280, 720), "preserve_ar": True}
        for key, value in (main or {}).items():
            if key not in ("format", "size", "stride", "preserve_ar"):
                raise ValueError(f"Bad key {key!r}: valid stream configuration keys are "
                                 "('format', 'size', 'stride', 'preserve_ar')")
            stream[key] = value
        w, h = stream["size"]
        stream["size"] = (w - w % 2, h - h % 2)  # align_stream(optimal=False)
        if lores is not None:
            lores = {"format": "YUV420", "size": stream["size"], "preserve_ar": False, **lores}
            lw, lh = lores["size"]
            lores["size"] = (lw - lw % 2, lh - lh % 2)
        if colour_space is None:  # picamera2 picks by resolution
            small = stream["size"][0] < 1280 or stream["size"][1] < 720
            colour_space = libcamera.ColorSpace.Smpte170m() if small else libcamera.ColorSpace.Rec709()
        merged = {"NoiseReductionMode": 1, "FrameDurationLimits": (33333, 33333)}
        merged.update(controls or {})
        return {"use_case": use_case, "transform": transform or libcamera.Transform(),
                "colour_space": colour_space, "buffer_count": buffer_count, "queue": queue,
                "main": stream, "lores": lores, "raw": raw, "controls": merged,
                "sensor": sensor, "display": display, "encode": encode}

    def configure(self, camera_config: Dict[str, Any]) -> None:
        if self.started:
            raise RuntimeError("Camera must be stopped before configuring")
        if not isinstance(camera_config, dict):
            raise TypeError("Invalid type for `camera_config` given")
        config = dict(camera_config)  # a shallow copy: the stream dicts are the caller's, updated in place
        _check_camera_config(config)
        adjusted = dict(WORLD.adjusted)  # libcamera's validate(): what the camera can give instead
        if "colour_space" in adjusted:
            config["colour_space"] = adjusted.pop("colour_space")
        main = config["main"]
        main.update(adjusted.get("main", {}))
        if main["format"] not in _BYTES_PER_PIXEL:
            raise RuntimeError(f"Bad format {main['format']} in stream main")
        if not isinstance(config["transform"], libcamera.Transform):
            raise RuntimeError("Transform has incorrect type")
        controls = dict(config["controls"])
        if "FrameRate" in controls:  # picamera2's virtual control for FrameDurationLimits
            rate = controls.pop("FrameRate")
            controls["FrameDurationLimits"] = (int(1e6 / rate), int(1e6 / rate))
        for name in controls:
            if name not in _KNOWN_CONTROLS:
                raise RuntimeError(f"Control {name} is not advertised by libcamera")
        config["controls"] = controls
        main["stride"] = -(-main["size"][0] * _BYTES_PER_PIXEL[main["format"]] // 64) * 64  # the ISP's alignment
        main["framesize"] = main["stride"] * main["size"][1]
        config["main"] = main
        if config.get("lores") is not None:
            lores = config["lores"]
            lores.update(adjusted.get("lores", {}))
            if lores["format"] not in ("YUV420", "YVU420"):
                raise RuntimeError("lores stream must be YUV")
            if lores["size"][0] > main["size"][0] or lores["size"][1] > main["size"][1]:
                raise RuntimeError("lores stream dimensions may not exceed main stream")
            lores["stride"] = -(-lores["size"][0] // 64) * 64  # the ISP's row alignment
            lores["framesize"] = lores["stride"] * lores["size"][1] * 3 // 2
            config["lores"] = lores
        self.camera_config = config
        self._applied = dict(controls)
        self._pending = []

    def set_controls(self, controls: Dict[str, Any]) -> None:
        """Queue controls; they reach the frames ``control_latency_frames`` later."""
        for name in controls:
            if name not in _KNOWN_CONTROLS:
                raise RuntimeError(f"Control {name} is not advertised by libcamera")
        with WORLD.lock:
            WORLD.set_controls_calls.append(dict(controls))
            self._pending.append((self._seq + 1 + WORLD.control_latency_frames, dict(controls)))

    def camera_configuration(self) -> Optional[Dict[str, Any]]:
        return self.camera_config

    def stream_configuration(self, name: str = "main") -> Dict[str, Any]:
        """``camera_config[name]``: granted format, size, ``stride`` and ``framesize`` (KeyError for no such name)."""
        return self.camera_config[name]

    @staticmethod
    def align_stream(stream_config: Dict[str, Any], optimal: bool = True) -> None:
        """Round the width down to the ISP's alignment (VC4: 32 px; YUV420 64, 4-byte RGB 16), the height to even."""
        align = 2
        if optimal:
            align = 32
            if stream_config["format"] in ("YUV420", "YVU420"):
                align *= 2
            elif stream_config["format"] in ("XBGR8888", "XRGB8888"):
                align //= 2
        w, h = stream_config["size"]
        stream_config["size"] = (w - w % align, h - h % 2)

    @staticmethod
    def align_configuration(config: Dict[str, Any], optimal: bool = True) -> None:
        Picamera2.align_stream(config["main"], optimal=optimal)
        if config.get("lores") is not None:
            Picamera2.align_stream(config["lores"], optimal=optimal)

    def wait(self, job: _Job, timeout: Optional[float] = None) -> Any:
        return job.get_result(timeout=timeout)

    def start(self, config: Any = None, show_preview: Any = False) -> None:
        if config is not None:
            self.configure(config)
        if self.camera_config is None:
            raise RuntimeError("Camera has not been configured")
        self.started = True
        # Sensor time starts in the past so stamps stay behind time.monotonic_ns().
        self._t0_ns = time.monotonic_ns() - 5_000_000_000

    def capture_request(
        self, wait: Any = None, signal_function: Any = None, flush: Any = None
    ) -> Any:
        return self._dispatch(None, wait, signal_function)

    def capture_array(self, name: str = "main", wait: Any = None, signal_function: Any = None) -> Any:
        """A copy of the next frame's ``name`` stream (``make_array``); the request is released inside."""
        return self._dispatch(lambda request: request.make_array(name), wait, signal_function)

    def capture_metadata(self, wait: Any = None, signal_function: Any = None) -> Any:
        """The next frame's metadata; the request is released inside."""
        return self._dispatch(lambda request: request.get_metadata(), wait, signal_function)

    def _dispatch(self, finish: Any, wait: Any, signal_function: Any) -> Any:
        """``dispatch_functions``: wait=None waits unless there is a signal function; a false wait gives the Job."""
        job = _Job(finish)
        with WORLD.lock:
            WORLD.capture_waits.append(wait)
            self._jobs.append(job)
            self._pump()
        if wait is None:  # dispatch_functions: wait unless a signal function was given
            wait = signal_function is None
        if not wait:  # False, or 0: the job itself
            return job
        timeout = None if wait is True else float(wait)
        return job.future.result(timeout=timeout)  # None: blocks until a frame or a cancel

    def cancel_all_and_flush(self) -> None:
        with WORLD.lock:
            for job in self._jobs:
                job.cancel()
            self._jobs = []

    def stop(self) -> None:
        self.stop_calls += 1
        if not self.started:
            return
        with WORLD.lock:
            blocked = bool(self._jobs) or WORLD.hang_stop
        if blocked:  # the stop job queues behind stale jobs that never complete
            WORLD.release.wait()
        self.started = False

    def close(self) -> None:
        if not self.is_open:
            return
        self.stop()
        with WORLD.lock:
            self.is_open = False
            WORLD.open_cameras.discard(self.camera_idx)

    def _buffers_free(self) -> bool:
        held = sum(1 for r in WORLD.outstanding if r.picam2 is self)
        return held < self.camera_config["buffer_count"]

    def _pump(self) -> None:
        """Complete queued jobs, oldest first, one new frame each (caller holds WORLD.lock)."""
        while self._jobs and self.started and not WORLD.stalled and self._buffers_free():
            job = self._jobs.pop(0)
            request = self._next_request()
            if job.finish is None:  # capture_request: the caller holds the request until it releases it
                WORLD.outstanding.append(request)
                job.future.set_result(request)
                continue
            try:
                result = job.finish(request)
            except Exception as exc:  # Job.execute: the exception is the job's result
                job.future.set_exception(exc)
            else:
                job.future.set_result(result)
            request.ref_count = 0  # capture_array_ / capture_metadata_ release it at once
            request._buffers = None

    def _exposure(self, w: int, h: int) -> Dict[str, Any]:
        """Apply due controls; the metadata of the frame about to be made."""
        while self._pending and self._pending[0][0] <= self._seq:
            self._applied.update(self._pending.pop(0)[1])
        c = self._applied
        manual_ae = c.get("AeEnable") is False or "ExposureTime" in c or "AnalogueGain" in c
        manual_awb = c.get("AwbEnable") is False or "ColourGains" in c
        frame_us = int(self.camera_config["controls"]["FrameDurationLimits"][0])
        auto_exp = WORLD.auto_exposure_us * WORLD.auto_drift(self._seq)  # AE's target exposure × gain
        if manual_ae:
            exp = min(int(c.get("ExposureTime", auto_exp)), frame_us)
            gain = float(c.get("AnalogueGain", WORLD.auto_gain))
        else:  # AE keeps the exposure inside the frame time and makes up with gain
            exp = int(min(auto_exp, frame_us))
            gain = WORLD.auto_gain * auto_exp / exp
        gains = tuple(c.get("ColourGains", WORLD.auto_colour_gains)) if manual_awb else WORLD.auto_colour_gains
        aw, ah = WORLD.pixel_array
        cw, ch = (aw, round(aw * h / w)) if aw * h <= ah * w else (round(ah * w / h), ah)
        return {
            "ExposureTime": exp, "AnalogueGain": gain, "DigitalGain": 1.0,
            "ColourGains": (float(gains[0]), float(gains[1])), "ColourTemperature": 4500, "Lux": 400.0,
            "AeLocked": True, "ScalerCrop": ((aw - cw) // 2, (ah - ch) // 2, cw, ch),
            "_scale": (exp * gain) / (auto_exp * WORLD.auto_gain),
            "_wb": (gains[0] / WORLD.auto_colour_gains[0], gains[1] / WORLD.auto_colour_gains[1]),
        }

    def _next_request(self) -> CompletedRequest:
        self._seq += 1 + WORLD.skip_next
        WORLD.skip_next = 0
        main = self.camera_config["main"]
        w, h = main["size"]
        exposure = self._exposure(w, h)
        scale, (wr, wb) = exposure.pop("_scale"), exposure.pop("_wb")
        rgb = np.asarray(WORLD.producer(self._seq, h, w), dtype=np.uint8)
        if abs(scale - 1) > 1e-9 or abs(wr - 1) > 1e-9 or abs(wb - 1) > 1e-9:
            k = np.array([scale * wr, scale, scale * wb], np.float32)
            rgb = np.clip(rgb.astype(np.float32) * k + 0.5, 0, 255).astype(np.uint8)
        transform = self.camera_config["transform"]
        if transform.hflip:
            rgb = rgb[:, ::-1]
        if transform.vflip:
            rgb = rgb[::-1]
        pixels = _to_format(rgb, main["format"])
        image = np.full((h, main["stride"]), 77, np.uint8)  # rows of stride bytes; the padding is junk
        image[:, : pixels.shape[1] * pixels.shape[2]] = pixels.reshape(h, -1)
        duration_us = int(self.camera_config["controls"]["FrameDurationLimits"][0])
        period_ns = WORLD.frame_period_ns or duration_us * 1000
        metadata = {
            "SensorTimestamp": self._t0_ns + self._seq * period_ns + WORLD.sensor_clock_offset_ns,
            "FrameDuration": period_ns // 1000,
            **exposure,
        }
        return CompletedRequest(self, image, metadata, self._lores(rgb))

    def _lores(self, rgb: np.ndarray) -> Optional[np.ndarray]:
        """The lores stream's I420 buffer for this frame's RGB content (None without a lores stream)."""
        lores = self.camera_config.get("lores")
        if lores is None:
            return None
        (w, h), stride = lores["size"], lores["stride"]
        bgr = np.ascontiguousarray(rgb[:, :, ::-1])
        if bgr.shape[:2] != (h, w):
            bgr = cv2.resize(bgr, (w, h), interpolation=cv2.INTER_AREA)
        flat = cv2.cvtColor(bgr, cv2.COLOR_BGR2YUV_I420).reshape(-1)
        n = (w // 2) * (h // 2)
        # the ISP filters chroma; OpenCV point-samples it: take it from the 2×2 block means instead
        block = cv2.resize(bgr, (w // 2, h // 2), interpolation=cv2.INTER_AREA)
        flat[w * h:] = cv2.transform(block, _CBCR).transpose(2, 0, 1).reshape(-1)
        buf = np.full((h * 3 // 2, stride), 77, np.uint8)
        buf[:h, :w] = flat[: w * h].reshape(h, w)
        chroma = buf[h:].reshape(2, h // 2, stride // 2)
        u, v = flat[w * h: w * h + n].reshape(h // 2, w // 2), flat[w * h + n:].reshape(h // 2, w // 2)
        chroma[0, :, : w // 2], chroma[1, :, : w // 2] = (u, v) if lores["format"] == "YUV420" else (v, u)
        return buf


def _check_camera_config(config: Dict[str, Any]) -> None:
    """picamera2's check_camera_config / check_stream_config: the RuntimeErrors a malformed config gets."""
    for name in ("colour_space", "transform", "main", "lores", "raw"):
        if name not in config:
            raise RuntimeError(f"{name!r} key expected in camera configuration")
    for name in ("main", "lores"):
        stream = config[name]
        if stream is None and name == "lores":
            continue
        if type(stream) is not dict:
            raise RuntimeError(name + " stream should be a dictionary")
        if "format" not in stream:
            raise RuntimeError("format not found in " + name + " stream")
        if "size" not in stream:
            raise RuntimeError("size not found in " + name + " stream")
        if type(stream["format"]) is not str:
            raise RuntimeError("format in " + name + " stream should be a string")
        size = stream["size"]
        if type(size) is not tuple or len(size) != 2:
            raise RuntimeError("size in " + name + " stream should be (width, height)")
        if size[0] % 2 or size[1] % 2:
            raise RuntimeError("width and height should be even")


def _to_format(rgb: np.ndarray, fmt: str) -> np.ndarray:
    """RGB content in the byte order picamera2's make_array returns for ``fmt``."""
    if fmt == "RGB888":
        return rgb[:, :, ::-1]  # [B, G, R]
    if fmt == "BGR888":
        return rgb
    alpha = np.full((*rgb.shape[:2], 1), 255, dtype=np.uint8)
    if fmt == "XBGR8888":
        return np.concatenate([rgb, alpha], axis=2)  # [R, G, B, 255]
    return np.concatenate([rgb[:, :, ::-1], alpha], axis=2)  # XRGB8888: [B, G, R, 255]
