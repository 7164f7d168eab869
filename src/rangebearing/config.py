"""Configuration: YAML in, one validated frozen dataclass tree out.

``yaml.safe_load`` → per-key checks → normalised values → cross-field checks.
Every problem is gathered and raised together in a single :class:`ConfigError`
that names the file and the key, so a user fixes a file in one pass.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, Callable, Dict, Mapping, Optional, Tuple, Union

import yaml

from . import config_checks as ck
from ._compat import frozen
from .core.types import CameraIntrinsics, LandmarkGeometry
from .errors import ConfigError

DEFAULT_PORT = 47800
METHODS = ("fast", "paper")
MODELS = ("pinhole", "paper")
SOURCES = ("recorded", "opencv", "picamera2", "synthetic")
WHITE_BALANCE = ("grey_world", "none")


@frozen
class DetectionConfig:
    """How bands are found. ``method: paper`` is the paper's pipeline as published."""

    method: str = "fast"
    median_ksize: int = 15
    downscale: int = 2
    white_balance: str = "grey_world"
    red_hue: Tuple[Tuple[int, int], ...] = ((0, 10), (165, 179))
    blue_hue: Tuple[Tuple[int, int], ...] = ((98, 132),)
    s_min: int = 90
    v_min: int = 25
    min_band_px: float = 3.0
    max_landmarks: int = 16
    tracking: bool = True
    full_scan_every: int = 8


@frozen
class ModelConfig:
    """Range and bearing from band centroids.

    ``pinhole``: range = f·spacing/(L·cos θ) + c, bearing = atan(x/f) after
    undistortion; in normalised image units, so it holds at any resolution.
    ``paper``: d_v = k/L, d_h = kh·px, θ = atan(d_h/d_v), d = d_v/cos θ, with
    k and kh in the pixels of the resolution they were fitted at.
    """

    kind: str = "pinhole"
    spacing_m: float = 0.055
    c_m: float = 0.0137
    k_px_m: float = 35.0
    kh_m_per_px: float = 0.00079
    cylinder_correction: bool = True
    envelope_range_m: Tuple[float, float] = (0.15, 2.0)
    envelope_bearing_rad: Tuple[float, float] = (-0.45, 0.45)


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
    timeout_s: float = 2.0
    retries: int = 5
    controls: Tuple[Tuple[str, Any], ...] = ()


@frozen
class PublishConfig:
    """Where readings go: unicast destinations and an opt-in multicast group."""

    robot_id: str = "zumo"
    unicast: Tuple[Tuple[str, int], ...] = (("127.0.0.1", DEFAULT_PORT),)
    multicast_group: str = ""
    multicast_port: int = DEFAULT_PORT
    multicast_ttl: int = 1
    multicast_interface: str = "127.0.0.1"


@frozen
class DaemonConfig:
    """The capture loop's housekeeping."""

    status_interval_s: float = 5.0
    echo: bool = False


@frozen
class Config:
    """The whole validated configuration."""

    camera: CameraIntrinsics = CameraIntrinsics()
    landmark: LandmarkGeometry = LandmarkGeometry()
    detection: DetectionConfig = DetectionConfig()
    model: ModelConfig = ModelConfig()
    source: SourceConfig = SourceConfig()
    publish: PublishConfig = PublishConfig()
    daemon: DaemonConfig = DaemonConfig()
    source_file: str = "<defaults>"


SCHEMA: Dict[str, Tuple[type, Dict[str, ck.Check]]] = {
    "camera": (
        CameraIntrinsics,
        {
            "width_px": ck.positive(True),
            "height_px": ck.positive(True),
            "fx_px": ck.positive(),
            "fy_px": ck.positive(),
            "cx_px": ck.number(0, 10000),
            "cy_px": ck.number(0, 10000),
            "distortion": ck.distortion,
        },
    ),
    "landmark": (
        LandmarkGeometry,
        {
            "height_m": ck.positive(),
            "diameter_m": ck.positive(),
            "band_height_m": ck.positive(),
        },
    ),
    "detection": (
        DetectionConfig,
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
            "max_landmarks": ck.positive(True),
            "tracking": ck.boolean,
            "full_scan_every": ck.positive(True),
        },
    ),
    "model": (
        ModelConfig,
        {
            "kind": ck.choice(*MODELS),
            "spacing_m": ck.positive(),
            "c_m": ck.number(-0.5, 0.5),
            "k_px_m": ck.positive(),
            "kh_m_per_px": ck.positive(),
            "cylinder_correction": ck.boolean,
            "envelope_range_m": ck.pair(0, 100),
            "envelope_bearing_rad": ck.pair(-math.pi, math.pi),
        },
    ),
    "source": (
        SourceConfig,
        {
            "kind": ck.choice(*SOURCES),
            "path": ck.string,
            "fps": ck.number(0, 1000),
            "loop": ck.boolean,
            "device": ck.string,
            "camera_num": ck.number(0, 16, integer=True),
            "width_px": ck.positive(True),
            "height_px": ck.positive(True),
            "hflip": ck.boolean,
            "vflip": ck.boolean,
            "buffer_count": ck.number(1, 16, integer=True),
            "timeout_s": ck.positive(),
            "retries": ck.number(0, 1000, integer=True),
            "controls": ck.controls,
        },
    ),
    "publish": (
        PublishConfig,
        {
            "robot_id": ck.string,
            "unicast": ck.destinations,
            "multicast_group": ck.string,
            "multicast_port": ck.number(1, 65535, integer=True),
            "multicast_ttl": ck.number(0, 255, integer=True),
            "multicast_interface": ck.string,
        },
    ),
    "daemon": (DaemonConfig, {"status_interval_s": ck.positive(), "echo": ck.boolean}),
}


def config_from_mapping(data: Any, source: str = "<config>", base: Optional[Config] = None) -> Config:
    """Validate a parsed YAML mapping into a :class:`Config`, starting from ``base``."""
    base = base or Config()
    problems: list[str] = []
    if data is None:
        data = {}
    if not isinstance(data, Mapping):
        raise ConfigError([f"top level must be a mapping of sections, got {type(data).__name__}"], source)
    sections: Dict[str, Any] = {}
    for name in data:
        if name not in SCHEMA:
            problems.append(f"unknown section {name!r} (known: {', '.join(SCHEMA)})")
    for name, (_cls, checks) in SCHEMA.items():
        current = getattr(base, name)
        raw = data.get(name)
        if raw is None:
            sections[name] = current
            continue
        if not isinstance(raw, Mapping):
            problems.append(f"{name}: must be a mapping, got {raw!r}")
            sections[name] = current
            continue
        values: Dict[str, Any] = {}
        for key, val in raw.items():
            if key not in checks:
                problems.append(f"{name}.{key}: unknown key (known: {', '.join(checks)})")
                continue
            try:
                values[key] = checks[key](val)
            except (ValueError, TypeError) as exc:
                problems.append(f"{name}.{key}: {exc}")
        sections[name] = dataclasses.replace(current, **values)
    cfg = Config(**sections, source_file=source)
    problems.extend(_cross_checks(cfg))
    if problems:
        raise ConfigError(problems, source)
    return cfg


def check(cfg: Config) -> None:
    """Re-run the cross-field checks on a config changed after loading (e.g. a command-line source).

    Raises
    ------
    ConfigError
        Naming every problem and the config's file.
    """
    problems = _cross_checks(cfg)
    if problems:
        raise ConfigError(problems, cfg.source_file)


def _cross_checks(cfg: Config) -> list[str]:
    p = []
    cam, lm = cfg.camera, cfg.landmark
    if not 0 <= cam.cx_px < cam.width_px:
        p.append(f"camera.cx_px: {cam.cx_px} is outside the image width {cam.width_px}")
    if not 0 <= cam.cy_px < cam.height_px:
        p.append(f"camera.cy_px: {cam.cy_px} is outside the image height {cam.height_px}")
    if 2 * lm.band_height_m >= lm.height_m:
        p.append("landmark.band_height_m: two bands do not fit in landmark.height_m")
    if cfg.source.kind in ("recorded",) and not cfg.source.path:
        p.append("source.path: required when source.kind is 'recorded'")
    if cfg.publish.multicast_group:
        parts = cfg.publish.multicast_group.split(".")
        if len(parts) != 4 or not all(x.isdigit() for x in parts) or not 224 <= int(parts[0]) <= 239:
            p.append(f"publish.multicast_group: {cfg.publish.multicast_group!r} is not an IPv4 multicast address")
    return p


def load_config(path: Union[str, Path, None] = None) -> Config:
    """Load and validate a YAML config; ``None`` gives the built-in defaults.

    Raises
    ------
    ConfigError
        The file is missing, unreadable, not YAML, or has invalid keys; the
        message lists every problem found.
    """
    if path is None:
        return Config()
    source = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError([f"cannot read file: {exc.strerror or exc}"], source) from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ConfigError([f"not valid YAML: {exc}".replace("\n", " ")], source) from None
    cfg = config_from_mapping(data, source)
    if cfg.source.path and not Path(cfg.source.path).is_absolute():  # relative to the file, not the cwd
        resolved = str((Path(path).parent / cfg.source.path).resolve())
        cfg = dataclasses.replace(cfg, source=dataclasses.replace(cfg.source, path=resolved))
    return cfg


def config_to_mapping(cfg: Config) -> Dict[str, Any]:
    """The YAML-ready mapping of a config (what ``calibrate`` writes)."""

    def plain(v: Any) -> Any:
        return [plain(x) for x in v] if isinstance(v, tuple) else v

    special: Dict[Tuple[str, str], Callable[[Any], Any]] = {
        ("source", "controls"): lambda v: {k: plain(x) for k, x in v},
        ("publish", "unicast"): lambda v: [f"{h}:{p}" for h, p in v],
    }
    out: Dict[str, Any] = {}
    for name in SCHEMA:
        section = getattr(cfg, name)
        out[name] = {}
        for key in SCHEMA[name][1]:
            out[name][key] = special.get((name, key), plain)(getattr(section, key))
    return out


def dump_config(cfg: Config) -> str:
    """The config as YAML text that :func:`load_config` accepts unchanged."""
    return yaml.safe_dump(config_to_mapping(cfg), sort_keys=False, default_flow_style=None)
