"""The world behind the clean-room fake `picamera2` (tests/fakes/picamera2_alt): cameras, sensor, scene, faults.

Written from the real library (github.com/raspberrypi/picamera2 at 3e6dff0) and its manual, without looking at
rangebearing's own fake or source. The package `picamera2` next to this module holds only the library's API; this
module is how a test sets up what the camera sees and how it fails:

- `configure(cameras=..., platform=..., scene=..., frame_duration_us=..., stop_after=..., busy=..., missing=...)`
  in process, or the environment variable PICAMERA2_ALT_RIG naming a JSON file with the same keys (read when the
  package is imported: a `rangebearing run` subprocess); `scene` is then a path to an .npy file (N, H, W, 3) RGB.
- `adjust`: {"main": {"format": "XBGR8888"}, "lores": {"format": "YVU420"}}: what libcamera's validate() grants
  instead of what was asked (picamera2.py:1207-1214 logs "Camera configuration has been adjusted!").
- `missing`: API extras a less complete fake might not have (`global_camera_info`, `camera_configuration`,
  `stream_configuration`, `MappedArray`, `align_configuration`, `camera_properties`, `sensor_modes`, `platform`,
  `cancel_all_and_flush`, `colour_space`): removed from the package when it is configured.

The scene is given in TRUE colour order (R, G, B); the fake packs it into each stream's format.
"""

from __future__ import annotations

import json
import os
import threading
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Union

import numpy as np

RIG_ENV = "PICAMERA2_ALT_RIG"


@dataclass
class SensorSpec:
    """One attached camera as libcamera describes it."""

    model: str = "imx708"
    camera_id: str = "/base/soc/i2c0mux/i2c@1/imx708@1a"
    location: int = 2
    rotation: int = 180
    usb: bool = False


# (format, size, fps) per sensor: the modes `picamera2 --list-cameras` / Picamera2.sensor_modes report.
SENSOR_MODES: dict[str, list[tuple[str, tuple[int, int], float]]] = {
    "imx708": [("SRGGB10_CSI2P", (1536, 864), 120.13), ("SRGGB10_CSI2P", (2304, 1296), 56.03),
               ("SRGGB10_CSI2P", (4608, 2592), 14.35)],
    "imx219": [("SBGGR10_CSI2P", (640, 480), 103.33), ("SBGGR10_CSI2P", (1640, 1232), 41.85),
               ("SBGGR10_CSI2P", (1920, 1080), 47.57), ("SBGGR10_CSI2P", (3280, 2464), 21.19)],
    "ov5647": [("SGBRG10_CSI2P", (640, 480), 58.92), ("SGBRG10_CSI2P", (1296, 972), 46.34),
               ("SGBRG10_CSI2P", (1920, 1080), 32.81), ("SGBRG10_CSI2P", (2592, 1944), 15.63)],
}

EXTRAS = ("global_camera_info", "camera_configuration", "stream_configuration", "MappedArray",
          "align_configuration", "camera_properties", "sensor_modes", "platform", "cancel_all_and_flush",
          "colour_space")


def colour_bars(height: int = 480, width: int = 640) -> np.ndarray:
    """Eight vertical bars in TRUE (R, G, B) order: white, yellow, cyan, green, magenta, red, blue, black."""
    bars = np.array([[255, 255, 255], [255, 255, 0], [0, 255, 255], [0, 255, 0],
                     [255, 0, 255], [255, 0, 0], [0, 0, 255], [0, 0, 0]], np.uint8)
    columns = (np.arange(width) * 8) // width
    return np.ascontiguousarray(np.broadcast_to(bars[columns][None], (height, width, 3)))


@dataclass
class Rig:
    """What the fake cameras see and do; one per process (module attribute RIG)."""

    cameras: list[SensorSpec] = field(default_factory=lambda: [SensorSpec()])
    platform: str = "vc4"  # "vc4" (Pi 4 and earlier) or "pisp" (Pi 5)
    scene: Union[list, Callable[[int], np.ndarray], None] = None  # RGB frames, cycled by sensor sequence
    frame_duration_us: Optional[int] = None  # overrides FrameDurationLimits (fast tests)
    stop_after: Optional[int] = None  # frames delivered, then the sensor goes silent (cable pulled)
    busy: set = field(default_factory=set)  # camera numbers another process holds
    missing: set = field(default_factory=set)
    adjust: dict = field(default_factory=dict)  # stream -> fields libcamera's validate() changes ("Adjusted")
    acquired: set = field(default_factory=set)  # camera numbers this process holds
    frames_delivered: int = 0
    instances: list = field(default_factory=list)  # every Picamera2 made since configure()
    ticks: int = 0  # event-loop rounds run (any camera)
    tick: threading.Condition = field(default_factory=threading.Condition)

    def wait_ticks(self, rounds: int, timeout_s: float = 60.0) -> bool:
        """Block until the cameras' event loops ran `rounds` more rounds (a frame in flight has landed)."""
        with self.tick:
            goal = self.ticks + rounds
            return self.tick.wait_for(lambda: self.ticks >= goal, timeout_s)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def frame(self, sequence: int) -> np.ndarray:
        """The scene at a sensor sequence number, RGB uint8 (H, W, 3)."""
        scene = self.scene
        if scene is None:
            return colour_bars()
        if callable(scene):
            return np.asarray(scene(sequence), np.uint8)
        return np.asarray(scene[sequence % len(scene)], np.uint8)


def held() -> int:
    """Requests capture_request handed out and not yet released, over every camera of the rig."""
    count = 0
    for cam in RIG.instances:
        with cam.request_lock:
            count += sum(1 for r in cam._handed if r.request is not None)
    return count


def register(cam: Any) -> None:
    """A new Picamera2 (called by its constructor)."""
    RIG.instances.append(cam)
    _EVERY.append(cam)


def shutdown() -> None:
    """Close every camera made in this process that is still open (a test's teardown), across configure()s."""
    while _EVERY:
        _EVERY.pop().close()


RIG = Rig()
_EVERY: list = []
_REMOVED: dict[tuple[Any, str], Any] = {}


def _strip(missing: set) -> None:
    """Remove (or put back) the API extras named in `missing`."""
    import picamera2
    from picamera2 import picamera2 as core

    places = {"global_camera_info": [core.Picamera2], "camera_configuration": [core.Picamera2],
              "stream_configuration": [core.Picamera2], "MappedArray": [picamera2],
              "align_configuration": [core.Picamera2], "camera_properties": [core.Picamera2],
              "sensor_modes": [core.Picamera2], "platform": [core.Picamera2],
              "cancel_all_and_flush": [core.Picamera2], "colour_space": []}
    for (owner, name), value in list(_REMOVED.items()):
        if name not in missing:
            setattr(owner, name, value)
            del _REMOVED[(owner, name)]
    for name in missing:
        if name not in EXTRAS:
            raise ValueError(f"unknown extra {name!r}; known: {EXTRAS}")
        for owner in places[name]:
            if (owner, name) not in _REMOVED and name in vars(owner):
                _REMOVED[(owner, name)] = vars(owner)[name]
                delattr(owner, name)


def configure(**settings: Any) -> Rig:
    """Reset the rig to defaults updated with `settings` (Rig's fields); returns it."""
    global RIG
    fresh = Rig()
    for key, value in settings.items():
        if not hasattr(fresh, key):
            raise ValueError(f"unknown rig setting {key!r}")
        if key in ("busy", "missing"):
            value = set(value)
        setattr(fresh, key, value)
    RIG = fresh
    _strip(fresh.missing)
    return fresh


def rig_file(path: str, scene_path: Optional[str] = None, **settings: Any) -> str:
    """Write a rig JSON for a subprocess (PICAMERA2_ALT_RIG); cameras as dicts of SensorSpec fields."""
    data = dict(settings)
    if "cameras" in data:
        data["cameras"] = [vars(c) if isinstance(c, SensorSpec) else c for c in data["cameras"]]
    for key in ("busy", "missing"):
        if key in data:
            data[key] = sorted(data[key])
    if scene_path is not None:
        data["scene"] = scene_path
    with open(path, "w") as out:
        json.dump(data, out)
    return path


def configure_from_env() -> None:
    """Apply PICAMERA2_ALT_RIG if set (called when the package is imported)."""
    path = os.environ.get(RIG_ENV)
    if not path:
        return
    with open(path) as source:
        data = json.load(source)
    if "cameras" in data:
        data["cameras"] = [SensorSpec(**c) for c in data["cameras"]]
    if isinstance(data.get("scene"), str):
        data["scene"] = list(np.load(data["scene"]))
    configure(**data)
