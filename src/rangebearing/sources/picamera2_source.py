"""The Raspberry Pi camera through Picamera2, with the library's sharp edges handled.

Written against picamera2 (raspberrypi/picamera2: picamera2/picamera2.py,
request.py, job.py) and the manual "The Picamera2 Library"; docs/picamera2.md
lists each behaviour relied on and what happens when a picamera2 lacks it:

* ``Picamera2(n)`` looks ``n`` up in ``global_camera_info()``, so a missing
  camera raises IndexError (after opening a pipe it does not close: the camera
  count is asked first); a busy camera fails in ``acquire()``: RuntimeError.
* ``capture_request()`` without ``wait=`` blocks forever. With ``wait=t`` the
  job's Future raises ``concurrent.futures.TimeoutError`` (the builtin
  TimeoutError only from Python 3.11) and the job stays queued: it would eat
  the next frame and leak its request, so ``cancel_all_and_flush()`` follows a
  timeout; a job already executed (popped, not yet signalled) is past that,
  so its request is released by the capture's ``signal_function``
  (:class:`~.camera_capture.LateRequest`). A false ``wait`` (``0``) returns
  the Job instead: ``timeout_s`` > 0.
* ``"RGB888"`` pixels are stored [B, G, R] (request.py maps RGB888 to PIL mode
  "BGR"), i.e. already OpenCV order. ``configure()`` may grant another format,
  size or colour space than asked (libcamera's ``validate()``): the streams are
  read as granted (:func:`~.camera_buffers.granted`); a main stream that is not
  RGB (a USB camera's YUYV, MJPEG) is a CameraError.
* ``MappedArray`` gives the main stream as (H, W, C) with the stride padding
  sliced off, lores YUV420 as (H·3/2, stride) with the padding left in.
* Every request must be released or the camera runs out of buffers.
* ``lores`` (YUV420 only on Pi 4 and earlier) is requested at the main size, so
  its U and V planes are at half resolution, the pipeline's search scale, in
  SMPTE 170M (set explicitly: picamera2 would pick Rec709 from 1280×720 up).
* Extras degrade to the core calls: no libcamera (colour space as picamera2
  picks it), no ``camera_configuration()`` (per stream, else as asked), no
  ``MappedArray`` (``make_array`` copies), no ``capture_request`` (``capture_array``).
* With ``in_place=True`` (the daemon) the request is held until the next
  ``read()`` (or ``close()``): a frame's arrays are views into camera memory
  valid until then; otherwise the frame is copied out and the request released.
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Any, Callable, Dict, Optional

import numpy as np

from ..config import SourceConfig
from ..core.yuv import Yuv420
from ..errors import CameraError, FrameError, SourceError
from .base import Frame, validate_frame
from .camera_buffers import ArrayRequest, Held, Layout, copied, granted
from .camera_capture import TIMEOUTS, Capturer, Notes, sensor_fields
from .camera_setup import (
    camera_controls,
    camera_count,
    camera_count_text,
    create_configuration,
    granted_configuration,
    import_module,
    optional_module,
)
from .sensor_time import SensorClock, boot_offset_ns, frames_missed, sensor_to_monotonic_ns

__all__ = ["Picamera2Source", "camera_controls", "frames_missed", "sensor_to_monotonic_ns"]
from .faults import TimeoutBudget

_log = logging.getLogger(__name__)


class Picamera2Source:
    """Frames from a Pi camera, BGR, stamped with the sensor time.

    Opening retries with exponential back-off (``backoff_s``, doubling, capped
    at ``max_backoff_s``) for ``cfg.retries`` more attempts when the camera is
    missing or busy; a ``sleep`` that returns True (a set ``threading.Event``'s
    ``wait``) stops the retries early. A capture that times out
    (``cfg.timeout_s``) raises FrameError; the ``cfg.retries``-th timeout in a
    row raises CameraError so the daemon exits and systemd restarts it.
    ``close()`` gives stop/close ``stop_timeout_s`` in a helper thread and logs
    if they hang.
    """

    def __init__(
        self,
        cfg: SourceConfig,
        *,
        sleep: Callable[[float], object] = time.sleep,
        clock: Callable[[], int] = time.monotonic_ns,
        backoff_s: float = 0.5,
        max_backoff_s: float = 2.0,  # a camera that comes back is found within 2 s
        stop_timeout_s: float = 3.0,
        in_place: bool = False,
    ) -> None:
        self._cfg = cfg
        self._in_place = in_place
        self._sleep = sleep
        self._clock = clock
        self._backoff_s = backoff_s
        self._max_backoff_s = max_backoff_s
        self._stop_timeout_s = stop_timeout_s
        self._cam: Any = None
        self._mapped: Any = None  # picamera2.MappedArray, or None (very old picamera2: make_array copies)
        self._held: Optional[Held] = None  # the request of the frame last returned, with its mapped streams
        self._layout: Optional[Layout] = None
        self._sensor_clock = SensorClock(0)
        self._prev_sensor_ns: Optional[int] = None
        self._next_index = 0
        self._dropped = 0
        self._budget = TimeoutBudget(f"camera {cfg.camera_num}", cfg.timeout_s, cfg.retries)
        self._notes = Notes(cfg.camera_num)
        self._capturer = Capturer(self._notes, cfg.timeout_s)
        self._metadata: Dict[str, Any] = {}

    @property
    def dropped(self) -> int:
        return self._dropped

    @property
    def metadata(self) -> Dict[str, Any]:
        """The last frame's request metadata (``ExposureTime``, ``AnalogueGain``, ``ColourGains``, ``ScalerCrop``…)."""
        return dict(self._metadata)

    def set_controls(self, controls: Dict[str, Any]) -> None:
        """Set libcamera controls on the running camera; they reach the frames a few frames later."""
        if self._cam is None:
            raise SourceError("Picamera2 source is not open")
        try:
            self._cam.set_controls(dict(controls))
        except (RuntimeError, ValueError, TypeError, AttributeError) as exc:
            raise CameraError(f"camera {self._cfg.camera_num}: cannot set controls {controls}: {exc}") from exc

    def open(self) -> None:
        """Acquire, configure and start the camera; CameraError if it cannot be done."""
        if self._cam is not None:
            return
        picamera2 = import_module("picamera2")
        cam = self._acquire(picamera2.Picamera2)
        self._mapped = getattr(picamera2, "MappedArray", None)
        cfg = self._cfg
        try:
            config = create_configuration(cam, cfg, optional_module("libcamera"))
            cam.configure(config)
            # what libcamera granted (validate() may adjust sizes, formats and the colour space)
            self._layout = granted(granted_configuration(cam, config), cfg.camera_num)
            cam.start()
        except CameraError:
            self._cam = cam
            self.close()
            raise
        except Exception as exc:  # deliberately broad: whatever the library raises, the camera is closed again
            self._cam = cam
            self.close()
            msg = f"camera {cfg.camera_num}: cannot configure and start: {exc}"
            raise CameraError(msg) from exc
        self._cam = cam
        self._sensor_clock = SensorClock(boot_offset_ns())  # a new shift too: the camera may restart its clock
        self._prev_sensor_ns = None
        self._next_index = 0
        self._dropped = 0
        self._budget.frame_arrived()

    def _acquire(self, picamera2_cls: Any) -> Any:
        n = self._cfg.camera_num
        attempts = self._cfg.retries + 1
        delay = self._backoff_s
        for attempt in range(1, attempts + 1):
            try:
                # Picamera2(n) looks n up in global_camera_info() only after opening a pipe it never closes
                # when n is not there: ask first (a camera plugged in later is found on a retry); the last
                # attempt asks the constructor itself, in case the count is wrong (one pipe at most leaks)
                if attempt < attempts and n >= camera_count(picamera2_cls):
                    raise IndexError(n)
                return picamera2_cls(n)
            except IndexError:
                error = CameraError(f"no camera {n} ({camera_count_text(picamera2_cls)} found)")
            except RuntimeError as exc:
                error = CameraError(f"camera {n} busy or failing to open ({exc}); "
                                    "is another process using it?")
            except Exception as exc:  # deliberately broad: a stand-in's own error for a missing or busy camera
                error = CameraError(f"camera {n} failed to open: {exc!r}")
            if attempt < attempts:
                _log.warning("%s; retrying in %.1f s (%d of %d)", error, delay, attempt, attempts)
                if self._sleep(delay):  # an Event.wait that was set: stop trying
                    break
                delay = min(delay * 2.0, self._max_backoff_s)
        raise error

    def read(self) -> Optional[Frame]:
        """The newest frame; FrameError on a timeout, CameraError on ``cfg.retries`` in a row.

        With ``in_place`` the frame's arrays stay valid until the next ``read()`` or ``close()``.
        """
        cam = self._cam
        if cam is None:
            raise SourceError("Picamera2 source is not open")
        self._release_held()  # the last frame is done with: its buffers go back to the camera
        try:
            request = self._capture(cam)
        except TIMEOUTS:
            self._capturer.flush(cam)  # the timed-out job is still queued: it would swallow a frame
            raise self._budget.timed_out() from None
        except (FrameError, CameraError):
            raise
        except Exception as exc:  # deliberately broad: whatever the library raises, the capture is retried
            raise CameraError(f"camera {self._cfg.camera_num}: capture failed: {exc!r}") from exc
        received_ns = self._clock()
        held = self._held = Held(request, self._mapped, self._notes)
        layout = self._layout
        try:
            array = held.array("main")
        except Exception as exc:  # deliberately broad: a request that cannot give its image is a skipped frame
            self._release_held()
            raise FrameError(f"camera {self._cfg.camera_num}: unusable request: {exc!r}") from exc
        metadata = self._capturer.metadata(request)
        self._mapped = held.mapped
        lores = self._lores(held) if layout.lores_size else None  # type: ignore[union-attr]
        self._budget.frame_arrived()
        self._metadata = metadata
        try:
            image, own_planes = layout.main(array)  # type: ignore[union-attr]
            image = validate_frame(image)  # a view if contiguous, else a copy
        except FrameError:
            self._release_held()
            raise
        search = layout.planes(lores) if lores is not None else own_planes  # type: ignore[union-attr]
        if not self._in_place:  # the caller may keep the frame: copy it out, give the buffers back now
            image = image if image.flags.owndata else image.copy()
            search = copied(search)
            self._release_held()
        return self._stamp(image, search, metadata, received_ns)

    def _release_held(self) -> None:
        held, self._held = self._held, None
        if held is not None:
            held.release()

    def _capture(self, cam: Any) -> Any:
        """The next completed request; a picamera2 without ``capture_request`` gives main arrays only."""
        capture = getattr(cam, "capture_request", None)
        if capture is not None:
            return self._capturer.request(capture)
        if self._layout is not None and self._layout.lores_size is not None:
            _log.warning("camera %d: no capture_request(): main stream only, searched in full",
                         self._cfg.camera_num)
            self._layout.lores_size = None
        return ArrayRequest(self._capturer.call(lambda **wait: cam.capture_array("main", **wait)))

    def _lores(self, held: Held) -> Optional[np.ndarray]:
        """The lores buffer, or None from now on if the request cannot give it (the main image is searched)."""
        try:
            return held.array("lores")
        except Exception as exc:  # deliberately broad: without lores the main image is searched
            _log.warning("camera %d: no lores stream in the request (%s): searching the main image",
                         self._cfg.camera_num, exc)
            self._layout.lores_size = None  # type: ignore[union-attr]
            return None

    def _stamp(self, image: np.ndarray, search: Optional[Yuv420], metadata: Dict[str, Any],
               received_ns: int) -> Frame:
        sensor_ns, duration_us = sensor_fields(metadata)
        if sensor_ns is None:
            t_ns = received_ns
        else:
            t_ns = self._sensor_clock.to_monotonic_ns(sensor_ns, received_ns)
            fps = self._cfg.fps
            period_ns = duration_us * 1e3 if duration_us else (1e9 / fps if fps > 0 else 0.0)
            missed = frames_missed(self._prev_sensor_ns, sensor_ns, period_ns)
            self._dropped += missed
            self._next_index += missed
            self._prev_sensor_ns = sensor_ns
        index = self._next_index
        self._next_index += 1
        return Frame(image=image, t_mono_ns=t_ns, index=index, name=str(index), lores_yuv420=search,
                     borrowed=self._held is not None)

    def close(self) -> None:
        """Flush, stop and close the camera, waiting at most ``stop_timeout_s``."""
        cam, self._cam = self._cam, None
        if cam is None:
            return
        self._release_held()
        done = threading.Event()

        def shut_down() -> None:
            # Each step runs even if the one before failed: the camera must be released.
            for step in ("cancel_all_and_flush", "stop", "close"):
                try:
                    if hasattr(cam, step):  # a stand-in picamera2 may lack cancel_all_and_flush
                        getattr(cam, step)()
                except Exception as exc:  # log and go on releasing
                    _log.warning("camera %d: %s() failed: %s", self._cfg.camera_num, step, exc)
            done.set()

        worker = threading.Thread(target=shut_down, name="picamera2-close", daemon=True)
        worker.start()
        if not done.wait(self._stop_timeout_s):
            _log.error(
                "camera %d did not stop within %.1f s; leaving it to the systemd watchdog",
                self._cfg.camera_num, self._stop_timeout_s,
            )
