"""Configuration: YAML in, one validated frozen dataclass tree out, and back to YAML.

``yaml.safe_load`` → per-key checks → normalised values → cross-field checks.
Every problem is gathered and raised together in a single :class:`ConfigError`
that names the file and the key, so a user fixes a file in one pass.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Callable, Dict, Mapping, Optional, Tuple, Union

import yaml

from ..errors import ConfigError
from . import checks as ck
from .schema import SCHEMA, Config


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
    if cfg.publish.multicast_group and not ck.is_ipv4_multicast(cfg.publish.multicast_group):
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
