"""The configuration's shape: one frozen dataclass per YAML section, and the per-key checks.

The five sections the pipeline needs (camera, landmark, detection, model,
identity) are the core's own parameter types (:mod:`rangebearing.core.params`,
:class:`~rangebearing.core.identity.IdentityParams`); the rest (source,
publish, daemon) belong to the application shell.
"""

from __future__ import annotations

import math
from typing import Any, Dict, Tuple, Union

from .._compat import frozen
from ..core.identity import IdentityParams
from ..core.params import METHODS, MODELS, WHITE_BALANCE, DetectionParams, ModelParams, PipelineParams
from ..core.types import CameraIntrinsics, LandmarkGeometry
from . import checks as ck

DEFAULT_PORT = 47800
SOURCES = ("recorded", "opencv", "picamera2", "synthetic")
MAX_FPS = 1000.0  # source.fps (and --fps) at most
MAX_CAMERA_NUM = 16  # source.camera_num (and picamera2:N) at most
# No frame for timeout_s × retries seconds: the daemon reopens the camera halfway, then exits
# cleanly for systemd to restart it, always before the unit's WatchdogSec=20s would SIGABRT it.
MAX_CAPTURE_BUDGET_S = 12.0
# detection.max_landmarks bounds a frame's search (its cost grows with it), not the datagram: the wire
# sends the nearest that fit one packet and counts the rest (net/fit.py)
MAX_LANDMARKS = 64


@frozen
class SourceConfig:
    """Where frames come from (the daemon and ``record``)."""

    kind: str = "picamera2"
    path: str = ""
    fps: float = 30.0
    loop: bool = False
    device: str = "0"
    camera_num: int = 0
    width_px: int = 640
    height_px: int = 480
    hflip: bool = False
    vflip: bool = False
    buffer_count: int = 4
    timeout_s: float = 1.0  # one capture's wait
    retries: int = 8  # no frame for timeout_s × retries: reopen the camera halfway, give up at the end
    open_timeout_s: float = 60.0  # at start, how long to wait for a missing or busy camera
    controls: Tuple[Tuple[str, Any], ...] = ()
    lores: bool = True  # picamera2: a YUV420 lores stream beside main, searched for bands (the ISP makes it)


@frozen
class ZenohConfig:
    """``publish.zenoh``: also publish every reading over Eclipse Zenoh (opt-in; docs/swarm.md)."""

    enabled: bool = False
    mode: str = "peer"  # peer | client
    connect: Tuple[str, ...] = ()  # routers or peers to dial, e.g. "tcp/192.168.1.10:7447"
    listen: Tuple[str, ...] = ()  # empty: Zenoh's default for the mode (every interface)
    scouting_multicast: bool = True  # find peers on the local network
    key: str = "rangebearing/{robot}/readings"


@frozen
class PublishConfig:
    """Where readings go: unicast destinations, an opt-in multicast group, opt-in Zenoh."""

    robot_id: str = "zumo"
    unicast: Tuple[Tuple[str, int], ...] = (("127.0.0.1", DEFAULT_PORT),)
    multicast_group: str = ""
    multicast_port: int = DEFAULT_PORT
    multicast_ttl: int = 1
    multicast_interface: str = "127.0.0.1"
    zenoh: ZenohConfig = ZenohConfig()


@frozen
class DaemonConfig:
    """The capture loop's housekeeping."""

    status_interval_s: float = 5.0
    echo: bool = False
    view_port: int = 0  # the live web page (docs/view.md); 0 = off
    view_host: str = "127.0.0.1"  # loopback: reach it through an SSH tunnel
    view_fps: float = 10.0  # frames drawn and sent per second while a browser watches
    # a periodic full scan runs after its frame's (tracked) readings are sent: latency, not CPU (docs/daemon-cost.md);
    # "auto": at source.fps >= 60 (latency-bound rates), not below (CPU-bound ones)
    scan_after_send: Union[bool, str] = "auto"


@frozen
class Config:
    """The whole validated configuration."""

    camera: CameraIntrinsics = CameraIntrinsics()
    landmark: LandmarkGeometry = LandmarkGeometry()
    detection: DetectionParams = DetectionParams()
    model: ModelParams = ModelParams()
    identity: IdentityParams = IdentityParams()
    source: SourceConfig = SourceConfig()
    publish: PublishConfig = PublishConfig()
    daemon: DaemonConfig = DaemonConfig()
    source_file: str = "<defaults>"

    @property
    def pipeline(self) -> PipelineParams:
        """What the pipeline needs: camera, landmark, detection, model and identity."""
        return PipelineParams(self.camera, self.landmark, self.detection, self.model, self.identity)


SCHEMA: Dict[str, Tuple[type, Dict[str, ck.Check]]] = {
    "camera": (
        CameraIntrinsics,
        {
            "width_px": ck.number(1, 10000, integer=True),  # as cx_px/cy_px: an image up to 10,000 px a side
            "height_px": ck.number(1, 10000, integer=True),
            "fx_px": ck.number(1, 1e6),  # a focal of 1e-300 px overflowed every ray, 1e308 px every pixel
            "fy_px": ck.number(1, 1e6),
            "cx_px": ck.number(0, 10000),
            "cy_px": ck.number(0, 10000),
            "distortion": ck.distortion,
        },
    ),
    "landmark": (
        LandmarkGeometry,
        {
            # a landmark from 1 mm to 10 m: a 1e-9 m one made the search look for nanometre bands (minutes a
            # frame), a 1e308 m one overflowed the projected size
            "height_m": ck.number(0.001, 10),
            "diameter_m": ck.number(0.001, 10),
            "band_height_m": ck.number(0.001, 10),
        },
    ),
    "detection": (
        DetectionParams,
        {
            "method": ck.choice(*METHODS),
            "median_ksize": ck.odd_ksize,
            "downscale": ck.number(1, 4, integer=True),
            "white_balance": ck.choice(*WHITE_BALANCE),
            "red_hue": ck.hue_ranges,
            "blue_hue": ck.hue_ranges,
            "s_min": ck.number(0, 255, integer=True),
            "v_min": ck.number(0, 255, integer=True),
            "min_band_px": ck.number(1, 100),
            "max_landmarks": ck.number(1, MAX_LANDMARKS, integer=True),
            "tracking": ck.boolean,
            "full_scan_every": ck.positive(True),
            "full_scan_interval_s": ck.number(0, 60),
        },
    ),
    "model": (
        ModelParams,
        {
            "kind": ck.choice(*MODELS),
            "spacing_m": ck.positive(),
            "c_m": ck.number(-0.5, 0.5),
            "k_px_m": ck.positive(),
            "kh_m_per_px": ck.positive(),
            "cylinder_correction": ck.boolean,
            "envelope_range_m": ck.pair(0, 100),
            "envelope_bearing_rad": ck.pair(-math.pi, math.pi),
            "centre_below_m": ck.number(-1, 1),
            "horizon_y_n": ck.number(-1, 1),
            "centre_sigma_m": ck.number(0, 1),
        },
    ),
    "identity": (
        IdentityParams,
        {
            "max_hidden_frames": ck.number(0, 1000, integer=True),
            "max_hidden_young_frames": ck.number(0, 1000, integer=True),
            "gate_d2": ck.number(above=0, hi=1000),
            "range_accel_mps2": ck.number(above=0, hi=100),
            "lateral_accel_mps2": ck.number(above=0, hi=100),
            "yaw_accel_radps2": ck.number(0, 100),
            "range_rate_prior_mps": ck.number(above=0, hi=100),
            "bearing_rate_prior_radps": ck.number(above=0, hi=100),
            "min_range_sigma_frac": ck.number(above=0, hi=1),
            "min_bearing_sigma_rad": ck.number(above=0, hi=1),
            "outlier_fraction": ck.number(above=0, hi=0.5),
            "outlier_range_frac": ck.number(above=0, hi=1),
            "outlier_bearing_rad": ck.number(above=0, hi=1),
            "young_penalty": ck.number(0, 1000),
            "twin_width_m": ck.number(0, 1),
            "nominal_dt_s": ck.number(above=0, hi=10),
            "max_dt_s": ck.number(above=0, hi=3600),
            "rate_after_updates": ck.number(2, 1000, integer=True),
        },
    ),
    "source": (
        SourceConfig,
        {
            "kind": ck.choice(*SOURCES),
            "path": ck.string,
            "fps": ck.number(0, MAX_FPS),
            "loop": ck.boolean,
            "device": ck.string,
            "camera_num": ck.number(0, MAX_CAMERA_NUM, integer=True),
            "width_px": ck.positive(True),
            "height_px": ck.positive(True),
            "hflip": ck.boolean,
            "vflip": ck.boolean,
            "buffer_count": ck.number(1, 16, integer=True),
            "timeout_s": ck.number(above=0, hi=4),
            "retries": ck.number(1, 100, integer=True),
            "open_timeout_s": ck.number(0, 80),  # the unit's TimeoutStartSec=90s must not cut it short
            "controls": ck.controls,
            "lores": ck.boolean,
        },
    ),
    "publish": (
        PublishConfig,
        {
            "robot_id": ck.robot_id,
            "unicast": ck.destinations,
            "multicast_group": ck.multicast_group,
            "multicast_port": ck.number(1, 65535, integer=True),
            "multicast_ttl": ck.number(0, 255, integer=True),
            "multicast_interface": ck.string,
            "zenoh": ck.Section(ZenohConfig, {
                "enabled": ck.boolean,
                "mode": ck.choice("peer", "client"),
                "connect": ck.endpoints,
                "listen": ck.endpoints,
                "scouting_multicast": ck.boolean,
                "key": ck.key_template,
            }),
        },
    ),
    "daemon": (
        DaemonConfig,
        {
            "status_interval_s": ck.number(above=0, hi=3600),
            "echo": ck.boolean,
            "view_port": ck.number(0, 65535, integer=True),
            "view_host": ck.string,
            "view_fps": ck.number(0.1, 60),
            "scan_after_send": ck.boolean_or("auto"),
        },
    ),
}
