"""Picamera2, as the real class behaves (github.com/raspberrypi/picamera2 3e6dff0, picamera2/picamera2.py:LINE).

The camera runs by itself once started: a thread (the real NullPreview event loop, previews/null_preview.py)
completes a request every frame if one is queued (else the frame is dropped), keeps at most one completed
request when `queue` is on (picamera2.py:1251-1257, 1479-1481) and runs queued jobs (process_requests,
picamera2.py:1411-1493). Capture calls are jobs (dispatch_functions, picamera2.py:1508-1537): without `wait`
they block forever; with a number they raise concurrent.futures.TimeoutError and the job STAYS queued (it will
take a later frame; the request it then holds is never released unless the caller cancels it with
cancel_all_and_flush, picamera2.py:1354-1366).
"""

from __future__ import annotations

import atexit
import os
import threading
import time
from functools import partial
from typing import Any, Optional

import numpy as np
import picamera2_alt_rig as rigmod

from . import formats
from . import platform as Platform
from .colour import ColorSpace, rgb_to_yuv420
from .job import Job
from .request import CompletedRequest, LibcameraRequest

_CONTROLS = {  # name: (min, max, default) as camera_controls reports them (picamera2.py:454-463)
    "FrameDurationLimits": (8333, 120000000, 33333), "ExposureTime": (9, 77193582, 20000),
    "AnalogueGain": (1.0, 16.0, 1.0), "AeEnable": (False, True, True), "AwbEnable": (False, True, True),
    "ColourGains": (0.0, 32.0, None), "Brightness": (-1.0, 1.0, 0.0), "Contrast": (0.0, 32.0, 1.0),
    "NoiseReductionMode": (0, 4, 0), "ScalerCrop": ((0, 0, 64, 64), (0, 0, 4608, 2592), (576, 0, 3456, 2592)),
}
_VIRTUAL = {"FrameRate": "FrameDurationLimits"}  # controls.py:18


class Picamera2:
    """One camera."""

    platform = Platform.get_platform()

    @staticmethod
    def global_camera_info() -> list[dict[str, Any]]:
        """Model/Location/Rotation/Id/Num per camera, sorted with USB cameras last (picamera2.py:296-312)."""
        cameras = [{"Model": c.model, "Location": c.location, "Rotation": c.rotation, "Id": c.camera_id, "Num": i}
                   for i, c in enumerate(rigmod.RIG.cameras)]
        return sorted(cameras, key=lambda cam: ("/usb" not in cam["Id"], cam["Id"]), reverse=True)

    def __init__(self, camera_num: int = 0, verbose_console=None, tuning=None, allocator=None) -> None:
        # picamera2.py:349-353: the notify pipe is made BEFORE the camera is looked up, so a missing camera
        # (IndexError below) leaks these two descriptors.
        self.notifyme_r, self.notifyme_w = os.pipe2(os.O_NONBLOCK)
        self._preview = None
        self.is_open = False
        # picamera2.py:354-355: IndexError when there is no camera `camera_num` (outside the try below).
        cameras = [{"Num": i, "Id": c.camera_id} for i, c in enumerate(rigmod.RIG.cameras)]
        cameras.sort(key=lambda cam: ("/usb" not in cam["Id"], cam["Id"]), reverse=True)
        camera_num = cameras[camera_num]["Num"]
        self.camera_idx = camera_num
        rigmod.register(self)
        self.request_lock = threading.Lock()
        self._reset_flags()
        try:
            self._open_camera()
        except Exception as error:  # picamera2.py:366-368
            raise RuntimeError("Camera __init__ sequence did not complete.") from error
        atexit.register(self.close)

    def _reset_flags(self) -> None:  # picamera2.py:382-406
        self.camera = None
        self.camera_ctrl_info: dict[str, tuple] = {}
        self.camera_config: dict[str, Any] = {}
        self.stream_map: dict[str, Any] = {}
        self.started = False
        self.stop_count = 0
        self.configure_count = 0
        self.frames = 0
        self._job_list: list[Job] = []
        self.completed_requests: list[CompletedRequest] = []
        self.lock = threading.Lock()
        self._event_loop_running = False
        self.camera_properties_: dict[str, Any] = {}
        self.controls: dict[str, Any] = {}
        self.sensor_modes_: list[dict[str, Any]] = []
        self._max_queue_len = 0
        self._free: list[LibcameraRequest] = []
        self._wake = threading.Condition()
        self._loop: Optional[threading.Thread] = None
        self._closing = False
        self._sequence = 0
        self._handed: list[CompletedRequest] = []  # what capture_request gave out (picamera2_alt_rig.held)

    def _open_camera(self) -> None:
        """Grab and acquire the camera (picamera2.py:524-577): RuntimeError when it is busy."""
        spec = rigmod.RIG.cameras[self.camera_idx]
        with rigmod.RIG.lock:
            if self.camera_idx in rigmod.RIG.busy or self.camera_idx in rigmod.RIG.acquired:
                # libcamera's Camera::acquire() -> -EBUSY; the python binding raises RuntimeError.
                raise RuntimeError("Failed to acquire camera: Device or resource busy")
            rigmod.RIG.acquired.add(self.camera_idx)
        self.camera = spec
        self.camera_ctrl_info = dict(_CONTROLS)
        modes = rigmod.SENSOR_MODES.get(spec.model, rigmod.SENSOR_MODES["imx708"])
        self._modes = modes
        self.sensor_resolution = max(modes, key=lambda m: m[1][0] * m[1][1])[1]
        self.camera_properties_ = {"Model": spec.model, "Location": spec.location, "Rotation": spec.rotation,
                                   "PixelArraySize": self.sensor_resolution, "UnitCellSize": (1400, 1400)}
        if not spec.usb:  # _is_rpi_camera (picamera2.py:762-764)
            self.camera_properties_["ColorFilterArrangement"] = 0
        self.is_open = True

    @property
    def camera_properties(self) -> dict[str, Any]:
        """{} once closed (picamera2.py:445-452)."""
        return {} if self.camera is None else self.camera_properties_

    @property
    def camera_controls(self) -> dict[str, tuple]:
        return dict(self.camera_ctrl_info)

    @property
    def sensor_modes(self) -> list[dict[str, Any]]:
        """The sensor's modes; the first call RECONFIGURES the camera (picamera2.py:580-615)."""
        if self.sensor_modes_:
            return self.sensor_modes_
        for fmt, size, fps in self._modes:
            self.configure(self.create_preview_configuration(raw={"format": fmt, "size": size}))
            self.sensor_modes_.append({"format": fmt, "unpacked": fmt.replace("_CSI2P", ""), "bit_depth": 10,
                                       "size": size, "fps": fps, "crop_limits": (0, 0, *self.sensor_resolution),
                                       "exposure_limits": (9, 77193582, None)})
        return self.sensor_modes_

    # ---------------------------------------------------------------- configurations (picamera2.py:737-935)
    @staticmethod
    def _make_initial_stream_config(stream_config: dict, updates: Optional[dict]) -> Optional[dict]:
        if updates is None:
            return None
        valid = ("format", "size", "stride", "preserve_ar")
        for key, value in updates.items():
            if key not in valid:
                raise ValueError(f"Bad key {key!r}: valid stream configuration keys are {valid}")
            stream_config[key] = value
        return stream_config

    def _create(self, main_default: dict, main, lores, raw, colour_space, buffer_count, controls, display,
                encode, queue, use_case, default_controls: dict) -> dict[str, Any]:
        if self.camera is None:
            raise RuntimeError("Camera not opened")
        main = self._make_initial_stream_config(main_default, main)
        self.align_stream(main, optimal=False)
        lores = self._make_initial_stream_config({"format": "YUV420", "size": main["size"], "preserve_ar": False},
                                                 lores)
        if lores is not None:
            self.align_stream(lores, optimal=False)
        if self.camera.usb:
            raw = None
        else:
            raw = dict(raw) if raw is not None else None
        config = {"use_case": use_case, "transform": None, "colour_space": colour_space,
                  "buffer_count": buffer_count, "queue": queue, "main": main, "lores": lores, "raw": raw,
                  "controls": {**default_controls, **controls}, "sensor": {}, "display": display, "encode": encode}
        return config

    def create_preview_configuration(self, main={}, lores=None, raw={}, transform=None,  # noqa: B006
                                     colour_space=None, buffer_count=4, controls={},  # noqa: B006
                                     display="main", encode="main", queue=True, sensor={},  # noqa: B006
                                     use_case="preview") -> dict[str, Any]:
        """XBGR8888 640x480, 4 buffers, sYCC (picamera2.py:777-826)."""
        return self._create({"format": "XBGR8888", "size": (640, 480), "preserve_ar": True}, main, lores, raw,
                            colour_space or ColorSpace.Sycc(), buffer_count, controls, display, encode, queue,
                            use_case, {"FrameDurationLimits": (100, 83333)})

    def create_still_configuration(self, main={}, lores=None, raw={}, transform=None,  # noqa: B006
                                   colour_space=None, buffer_count=1, controls={},  # noqa: B006
                                   display=None, encode=None, queue=True, sensor={},  # noqa: B006
                                   use_case="still") -> dict[str, Any]:
        """BGR888 at the full sensor size, 1 buffer, sYCC (picamera2.py:828-879)."""
        return self._create({"format": "BGR888", "size": self.sensor_resolution if self.camera else None,
                             "preserve_ar": True}, main, lores, raw, colour_space or ColorSpace.Sycc(),
                            buffer_count, controls, display, encode, queue, use_case,
                            {"FrameDurationLimits": (100, 1000000 * 1000)})

    def create_video_configuration(self, main={}, lores=None, raw={}, transform=None,  # noqa: B006
                                   colour_space=None, buffer_count=6, controls={},  # noqa: B006
                                   display="main", encode="main", queue=True, sensor={},  # noqa: B006
                                   use_case="video") -> dict[str, Any]:
        """XBGR8888 1280x720, 6 buffers, SMPTE170M below 1280x720 else Rec709, 30 fps (picamera2.py:881-935)."""
        config = self._create({"format": "XBGR8888", "size": (1280, 720), "preserve_ar": True}, main, lores, raw,
                              colour_space, buffer_count, controls, display, encode, queue, use_case,
                              {"FrameDurationLimits": (33333, 33333)})
        if config["colour_space"] is None:
            w, h = config["main"]["size"]
            config["colour_space"] = ColorSpace.Smpte170m() if w < 1280 or h < 720 else ColorSpace.Rec709()
        return config

    @staticmethod
    def align_stream(stream_config: dict, optimal: bool = True) -> None:
        """Width to the ISP's alignment (VC4 32, PiSP 64 bytes a plane) or just even (picamera2.py:1087-1100)."""
        if optimal:
            align = 32 if Platform.get_platform() == Platform.Platform.VC4 else 64
            if stream_config["format"] in ("YUV420", "YVU420"):
                align *= 2
            elif stream_config["format"] in ("XBGR8888", "XRGB8888"):
                align //= 2
        else:
            align = 2
        size = stream_config["size"]
        stream_config["size"] = (size[0] - size[0] % align, size[1] - size[1] % 2)

    @staticmethod
    def align_configuration(config: dict, optimal: bool = True) -> None:
        """align_stream on main and lores (picamera2.py:1102-1106)."""
        Picamera2.align_stream(config["main"], optimal=optimal)
        if config.get("lores") is not None:
            Picamera2.align_stream(config["lores"], optimal=optimal)

    @staticmethod
    def _check_stream(stream: Any, name: str) -> None:  # picamera2.py:937-963
        if type(stream) is not dict:
            raise RuntimeError(name + " stream should be a dictionary")
        if "format" not in stream:
            raise RuntimeError("format not found in " + name + " stream")
        if "size" not in stream:
            raise RuntimeError("size not found in " + name + " stream")
        fmt = stream["format"]
        if type(fmt) is not str:
            raise RuntimeError("format in " + name + " stream should be a string")
        if name == "raw":
            if not formats.is_raw(fmt):
                raise RuntimeError("Unrecognised raw format " + fmt)
        elif not formats.is_YUV(fmt) and not formats.is_RGB(fmt) and fmt != "MJPEG":
            raise RuntimeError("Bad format " + fmt + " in stream " + name)
        size = stream["size"]
        if type(size) is not tuple or len(size) != 2:  # a list is refused
            raise RuntimeError("size in " + name + " stream should be (width, height)")
        if size[0] % 2 or size[1] % 2:
            raise RuntimeError("width and height should be even")

    def _check_config(self, config: dict) -> None:  # picamera2.py:965-994
        for name in ("colour_space", "transform", "main", "lores", "raw"):
            if name not in config:
                raise RuntimeError(f"{name!r} key expected in camera configuration")
        self._check_stream(config["main"], "main")
        if config["lores"] is not None:
            self._check_stream(config["lores"], "lores")
            (mw, mh), (lw, lh) = config["main"]["size"], config["lores"]["size"]
            if lw > mw or lh > mh:
                raise RuntimeError("lores stream dimensions may not exceed main stream")
            if Platform.get_platform() == Platform.Platform.VC4 and not formats.is_YUV(config["lores"]["format"]):
                raise RuntimeError("lores stream must be YUV")
        if config["raw"] is not None and config["raw"].get("format") is not None:
            self._check_stream(config["raw"], "raw")

    @staticmethod
    def _stride(fmt: str, width: int) -> tuple[int, int]:
        """(stride, frame bytes per row of height): rows padded to the ISP's plane alignment.

        align_stream calls 32 (VC4) / 64 (PiSP) bytes a plane "the hardware behaviour" (picamera2.py:1089-1095);
        a YUV420 buffer's chroma planes have half the Y stride (request.py save(): strides[0] // 2), so the Y
        stride is padded to twice that.
        """
        align = 32 if Platform.get_platform() == Platform.Platform.VC4 else 64
        if fmt in ("YUV420", "YVU420"):
            align *= 2
            bpp = 1
        else:
            bpp = {"BGR888": 3, "RGB888": 3, "XBGR8888": 4, "XRGB8888": 4}.get(fmt, 2)
        stride = -(-width * bpp // align) * align
        return stride, stride

    def configure(self, camera_config: Any = None) -> None:
        """Validate and apply a configuration; fills in stride/framesize (picamera2.py:1159-1284)."""
        if self.started:
            raise RuntimeError("Camera must be stopped before configuring")
        if camera_config is None or isinstance(camera_config, str):
            camera_config = {"still": self.create_still_configuration,
                             "video": self.create_video_configuration}.get(camera_config or "preview",
                                                                           self.create_preview_configuration)()
        if not isinstance(camera_config, dict):
            raise TypeError("Invalid type for `camera_config` given")
        # picamera2.py:1186: a SHALLOW copy: the caller's stream dicts get the granted stride/size written in
        config = camera_config.copy()
        if config.get("raw") is not None:
            config["raw"].setdefault("format", self._modes[0][0])
            config["raw"].setdefault("size", config["main"]["size"])
        if self.camera.usb:
            config["raw"] = None
        self.camera_config = {}
        self._check_config(config)
        for name in ("main", "lores", "raw"):
            stream = config[name]
            if stream is None:
                continue
            stream.update(rigmod.RIG.adjust.get(name, {}))  # validate() -> Adjusted (picamera2.py:1207-1214)
            if name == "raw":
                stream["size"] = tuple(stream["size"])
                stream["stride"] = stream["size"][0] * 2
                stream["framesize"] = stream["stride"] * stream["size"][1]
                continue
            stride, _ = self._stride(stream["format"], stream["size"][0])
            rows = stream["size"][1] * 3 // 2 if stream["format"] in ("YUV420", "YVU420") else stream["size"][1]
            stream["stride"] = stride
            stream["framesize"] = stride * rows
        self._colour_space = config.get("colour_space")  # what the ISP encodes with, reported or not
        if "colour_space" in rigmod.RIG.missing:
            config.pop("colour_space", None)
        elif self.camera.usb:
            config["colour_space"] = None  # utils.py:32: "USB webcams might have a None colour space"
        controls = {}
        for name, value in config.get("controls", {}).items():
            self._check_control(name)
            controls[_VIRTUAL.get(name, name)] = _fps_to_durations(value) if name == "FrameRate" else value
        config["controls"] = controls
        self.controls = dict(controls)
        self.stream_map = {"main": "main", "lores": "lores" if config["lores"] else None,
                           "raw": "raw" if config["raw"] else None}
        self._max_queue_len = 1 if config["queue"] and config["buffer_count"] > 1 else 0
        # Row padding is never written: it holds whatever the buffer held (0xA5 here), as on the ISP.
        self._buffers = [{name: np.full(config[name]["framesize"], 0xA5, np.uint8) for name in ("main", "lores")
                          if config[name] is not None} for _ in range(config["buffer_count"])]
        self.camera_config = config
        self.configure_count += 1

    def camera_configuration(self) -> dict[str, Any]:
        """The configuration as granted (picamera2.py:1286-1288)."""
        return self.camera_config

    def stream_configuration(self, name: str = "main") -> dict[str, Any]:
        """One stream's granted configuration incl. stride (picamera2.py:1290-1292); KeyError if unknown."""
        return self.camera_config[name]

    def _check_control(self, name: str) -> None:  # controls.py:26-35
        if _VIRTUAL.get(name, name) not in self.camera_ctrl_info:
            raise RuntimeError(f"Control {name} is not advertised by libcamera")

    def set_controls(self, controls: dict[str, Any]) -> None:
        """Controls for the next requests (picamera2.py:1407-1409, controls.py:54-66)."""
        if not isinstance(controls, dict):
            raise RuntimeError(f"Cannot update controls with {type(controls)} type")
        for name, value in controls.items():
            self._check_control(name)
            self.controls[_VIRTUAL.get(name, name)] = _fps_to_durations(value) if name == "FrameRate" else value

    # ---------------------------------------------------------------- running
    def start(self, config: Any = None, show_preview: Any = False) -> None:
        """Configure if needed, start the event loop unless show_preview is None, start (picamera2.py:1326-1352).

        show_preview=None runs NO event loop: frames are then never delivered (the caller must run one).
        """
        if not self.camera_config and config is None:
            config = "preview"
        if config is not None:
            self.configure(config)
        if not self.camera_config:
            raise RuntimeError("Camera has not been configured")
        if show_preview is not None and not self._event_loop_running:
            self._event_loop_running = True
            self._loop = threading.Thread(target=self._event_loop, name="fake-picamera2-null-preview", daemon=True)
            self._loop.start()
        if self.started:
            return
        with self.lock:
            self._free = [LibcameraRequest(buffers) for buffers in self._buffers]
            self.started = True
        with self._wake:
            self._wake.notify_all()

    def stop(self) -> None:
        """Stop the camera; held requests are not recycled, queued jobs stay queued (picamera2.py:1368-1405)."""
        if not self.started:
            return
        with self.lock:
            self.stop_count += 1
            self.started = False
            self._free = []
            while self.completed_requests:
                self.completed_requests.pop(0).release()

    def close(self) -> None:
        """Stop, stop the event loop, release the camera (picamera2.py:704-734)."""
        atexit.unregister(self.close)
        if self._loop is not None:
            self._closing = True
            with self._wake:
                self._wake.notify_all()
            self._loop.join()
            self._loop = None
            self._event_loop_running = False
        if not self.is_open:
            return
        self.stop()
        with rigmod.RIG.lock:
            rigmod.RIG.acquired.discard(self.camera_idx)
        self.is_open = False
        self.camera = None
        self.camera_config = {}
        self.stream_map = {}
        os.close(self.notifyme_r)
        os.close(self.notifyme_w)

    def __enter__(self) -> Picamera2:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __del__(self) -> None:
        if getattr(self, "is_open", False) or getattr(self, "_loop", None) is not None:
            self.close()

    def _queue_request(self, request: LibcameraRequest) -> None:
        with self._wake:
            self._free.append(request)

    def _frame_duration_us(self) -> int:
        if rigmod.RIG.frame_duration_us is not None:
            return int(rigmod.RIG.frame_duration_us)
        low, _high = self.controls.get("FrameDurationLimits", (33333, 33333))
        size = self.camera_config["main"]["size"]
        fitting = [m for m in self._modes if m[1][0] >= size[0] and m[1][1] >= size[1]] or self._modes[-1:]
        return int(max(low, 1e6 / max(fitting, key=lambda m: m[2])[2]))

    def _event_loop(self) -> None:
        next_frame = time.monotonic()
        while not self._closing:
            new: list[CompletedRequest] = []
            with self._wake:
                wait = next_frame - time.monotonic()
                if wait > 0:
                    self._wake.wait(wait)
                if self._closing:
                    return
            now = time.monotonic()
            if self.started and now >= next_frame:
                duration = self._frame_duration_us()
                next_frame = max(next_frame + duration * 1e-6, now)
                request = self._expose(now, duration)
                if request is not None:
                    new.append(request)
            elif not self.started:
                next_frame = now + 0.05
            self._process_requests(new)
            with rigmod.RIG.tick:
                rigmod.RIG.ticks += 1
                rigmod.RIG.tick.notify_all()

    def _expose(self, now: float, duration_us: int) -> Optional[CompletedRequest]:
        """Complete one frame into a queued request; None if the sensor is silent or no request is queued."""
        rig = rigmod.RIG
        self._sequence += 1
        with rig.lock:
            if rig.stop_after is not None and rig.frames_delivered >= rig.stop_after:
                return None
        with self._wake:
            if not self._free or not self.started:
                return None  # no buffer queued: the frame is dropped
            request = self._free.pop(0)
        scene = rig.frame(self._sequence)
        config = self.camera_config
        for name, buffer in request.buffers.items():
            _pack(scene, config[name], buffer, self._colour_space)
        exposure = min(20000, duration_us - 500)
        request.metadata = {
            "SensorTimestamp": int(now * 1e9) - 2_000_000,  # CLOCK_MONOTONIC ns, start of readout (1552-1564)
            "FrameDuration": duration_us, "ExposureTime": exposure, "AnalogueGain": 2.0, "DigitalGain": 1.0,
            "ColourGains": (1.8, 1.6), "ColourTemperature": 4500, "Lux": 400.0, "AeLocked": True,
            "SensorBlackLevels": (4096, 4096, 4096, 4096), "ScalerCrop": (576, 0, 3456, 2592),
        }
        with rig.lock:
            rig.frames_delivered += 1
        return CompletedRequest(request, self)

    def _process_requests(self, requests: list[CompletedRequest]) -> None:
        """Keep the newest, run jobs, recycle the rest (picamera2.py:1411-1493)."""
        finished = []
        with self.lock:
            stale = [r for r in requests if r.stop_count != self.stop_count or not self.started]
            for request in stale:  # completed as the camera stopped: flushed, never delivered (1382-1386)
                request.release()
            requests = [r for r in requests if r not in stale]
            for request in requests:
                request.acquire()
            self.completed_requests += requests
            self.frames += len(requests)
            while self._job_list:
                if self._job_list[0].execute():
                    finished.append(self._job_list.pop(0))
                else:
                    break
            for request in requests:
                request.release()
            while len(self.completed_requests) > self._max_queue_len:
                self.completed_requests.pop(0).release()
        for job in finished:
            job.signal()

    def dispatch_functions(self, functions: list, wait: Any, signal_function=None, immediate: bool = False) -> Any:
        """Queue a job; wait=None/True blocks forever, a number times out, False/0 returns the Job (1508-1537)."""
        if wait is None:
            wait = signal_function is None
        timeout = None if wait is True else wait
        with self.lock:
            only_job = not self._job_list
            job = Job(functions, signal_function)
            self._job_list.append(job)
            prod = only_job and (self.completed_requests or immediate)
        if prod:
            with self._wake:
                self._wake.notify_all()
        return job.get_result(timeout=timeout) if wait else job

    def wait(self, job: Job, timeout: Optional[float] = None) -> Any:
        """The result of a Job from wait=False (picamera2.py:1499-1506)."""
        return job.get_result(timeout=timeout)

    def cancel_all_and_flush(self) -> None:
        """Cancel every queued job (picamera2.py:1354-1366)."""
        with self.lock:
            for job in self._job_list:
                job.cancel()
            self._job_list = []

    def _wait_for_timestamp(self, timestamp_ns: Optional[int]) -> tuple[bool, Any]:  # picamera2.py:1552-1564
        if not timestamp_ns:
            return (True, None)
        while self.completed_requests:
            md = self.completed_requests[0].get_metadata()
            if md["SensorTimestamp"] - 1000 * md["ExposureTime"] >= timestamp_ns:
                return (True, None)
            self.completed_requests.pop(0).release()
        return (False, None)

    def _capture_request(self) -> tuple[bool, Any]:  # picamera2.py:1831-1835
        if not self.completed_requests:
            return (False, None)
        request = self.completed_requests.pop(0)
        self._handed = [r for r in self._handed if r.request is not None] + [request]  # rig bookkeeping
        return (True, request)

    def capture_request(self, wait: Any = None, signal_function=None, flush: Any = None) -> Any:
        """The next completed request; the caller must release() it (picamera2.py:1855-1865)."""
        if flush is True:
            flush = time.monotonic_ns()
        return self.dispatch_functions([partial(self._wait_for_timestamp, flush), self._capture_request], wait,
                                       signal_function)

    def _capture_array(self, name: str) -> tuple[bool, Any]:  # picamera2.py:2163-2169
        if not self.completed_requests:
            return (False, None)
        request = self.completed_requests.pop(0)
        try:
            return (True, request.make_array(name))
        finally:
            request.release()

    def capture_array(self, name: str = "main", wait: Any = None, signal_function=None) -> Any:
        """A copy of the next frame's stream (picamera2.py:2189-2191)."""
        return self.dispatch_functions([partial(self._capture_array, name)], wait, signal_function)

    def capture_metadata(self, wait: Any = None, signal_function=None) -> Any:
        """The next frame's metadata (picamera2.py:1962-1988)."""
        def metadata() -> tuple[bool, Any]:
            if not self.completed_requests:
                return (False, None)
            request = self.completed_requests.pop(0)
            result = request.get_metadata()
            request.release()
            return (True, result)

        return self.dispatch_functions([metadata], wait, signal_function)


def _fps_to_durations(fps: Any) -> tuple[int, int]:  # controls.py:8-11
    if not isinstance(fps, (tuple, list)):
        fps = (fps, fps)
    return (int(1000000 / fps[1]), int(1000000 / fps[0]))


def _resize(rgb: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """The ISP's scaler, nearest sample of the same field of view (main and lores show the same crop)."""
    w, h = size
    if rgb.shape[1] == w and rgb.shape[0] == h:
        return rgb
    rows = ((np.arange(h) + 0.5) * rgb.shape[0] / h).astype(np.intp)
    cols = ((np.arange(w) + 0.5) * rgb.shape[1] / w).astype(np.intp)
    return rgb[rows][:, cols]


def _pack(scene: np.ndarray, stream: dict, buffer: np.ndarray, space: Optional[ColorSpace]) -> None:
    """Write the scene into a flat buffer in the stream's format, stride and byte order.

    Byte orders in memory follow the PIL modes picamera2 gives each format (request.py:345-350):
    RGB888 -> "BGR", BGR888 -> "RGB", XBGR8888 -> "RGBX", XRGB8888 -> "BGRX".
    """
    fmt, (w, h), stride = stream["format"], stream["size"], stream["stride"]
    rgb = _resize(scene, (w, h))
    if fmt in ("YUV420", "YVU420"):
        y, u, v = rgb_to_yuv420(rgb, space)
        if fmt == "YVU420":
            u, v = v, u
        buffer[: stride * h].reshape(h, stride)[:, :w] = y
        half = stride // 2
        chroma = h // 2 * half
        buffer[stride * h: stride * h + chroma].reshape(h // 2, half)[:, : w // 2] = u
        buffer[stride * h + chroma: stride * h + 2 * chroma].reshape(h // 2, half)[:, : w // 2] = v
        return
    order = {"RGB888": (2, 1, 0), "BGR888": (0, 1, 2), "XBGR8888": (0, 1, 2), "XRGB8888": (2, 1, 0)}[fmt]
    channels = 3 if fmt in ("RGB888", "BGR888") else 4
    rows = buffer[: stride * h].reshape(h, stride)[:, : w * channels].reshape(h, w, channels)
    rows[..., :3] = rgb[..., list(order)]
    if channels == 4:
        rows[..., 3] = 255
