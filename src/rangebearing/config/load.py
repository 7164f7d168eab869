"""Configuration: YAML in, one validated frozen dataclass tree out, and back to YAML.

A bounded safe YAML read (:mod:`.yaml_safe`) → per-key checks → normalised
values → cross-field checks (including what a deployment can reach: a datagram
that fits one packet, a capture budget inside the watchdog). Every problem is
gathered and raised together in a single :class:`ConfigError` that names the
file and the key, so a user fixes a file in one pass; nothing else escapes.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Callable, Dict, Mapping, Optional, Tuple, Union

from ..errors import ConfigError
from . import checks as ck
from .camera_model import PRESET_KEYS, split_camera
from .parsed_cache import parsed
from .schema import MAX_CAPTURE_BUDGET_S, SCHEMA, Config


def config_from_mapping(data: Any, source: str = "<config>", base: Optional[Config] = None) -> Config:
    """Validate a parsed YAML mapping into a :class:`Config`, starting from ``base``."""
    base = base or Config()
    problems: list[str] = []
    if data is None:
        data = {}
    if not isinstance(data, Mapping):
        raise ConfigError([f"top level must be a mapping of sections, got {type(data).__name__}"], source)
    sections: Dict[str, Any] = {}
    cam_raw = data.get("camera")
    if isinstance(cam_raw, Mapping) and any(k in cam_raw for k in PRESET_KEYS):  # camera.model and its crops
        preset, rest = split_camera(cam_raw, data.get("source"), base.camera, problems)
        base = dataclasses.replace(base, camera=preset)
        data = {**data, "camera": rest}
    for name in data:
        if name not in SCHEMA:
            problems.append(f"unknown section {ck.show(name)} (known: {', '.join(SCHEMA)})")
    for name, (_cls, checks) in SCHEMA.items():
        sections[name] = _section(name, getattr(base, name), data.get(name), checks, problems)
    cfg = Config(**sections, source_file=source)
    problems.extend(_cross_checks(cfg))
    if problems:
        raise ConfigError(problems, source)
    return cfg


def _key(key: Any) -> str:
    """A YAML key as a message shows it: plain when it is short text, else cut and quoted."""
    return key if isinstance(key, str) and key.isprintable() and len(key) <= 40 else ck.show(key)


def _section(name: str, current: Any, raw: Any, checks: Mapping[str, Any], problems: list) -> Any:
    """``current`` with the checked values of ``raw``; each problem is named ``name.key``."""
    if raw is None:
        return current
    if not isinstance(raw, Mapping):
        problems.append(f"{name}: must be a mapping, got {ck.show(raw)}")
        return current
    values: Dict[str, Any] = {}
    listed = False  # the known keys are listed once per section: a misplaced block would repeat them
    for key, val in raw.items():
        if key not in checks:
            known = [*checks, *PRESET_KEYS] if name == "camera" else list(checks)
            hint = "known keys above" if listed else f"known: {', '.join(known)}"
            problems.append(f"{name}.{_key(key)}: unknown key ({hint})")
            listed = True
            continue
        if isinstance(checks[key], ck.Section):  # a nested section: publish.zenoh
            values[key] = _section(f"{name}.{key}", getattr(current, key), val, checks[key].checks, problems)
            continue
        try:
            values[key] = checks[key](val)
        except ck.Invalid as exc:  # every bad entry of a list, each named
            problems.extend(f"{name}.{key}{where}: {msg}" for where, msg in exc.problems)
        except (ValueError, TypeError) as exc:
            problems.append(f"{name}.{key}: {exc}")
    return dataclasses.replace(current, **values)


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
        p.append(f"publish.multicast_group: {ck.show(cfg.publish.multicast_group)} is not an IPv4 multicast address")
    src = cfg.source
    budget_s = src.timeout_s * src.retries
    if budget_s > MAX_CAPTURE_BUDGET_S:
        p.append(f"source.timeout_s × source.retries: {budget_s:g} s without a frame before the daemon gives up; "
                 f"at most {MAX_CAPTURE_BUDGET_S:g} s, clearly inside the service's WatchdogSec=20s")
    p.extend(_datagram_fits(cfg))
    p.extend(_identity_checks(cfg))
    z = cfg.publish.zenoh
    if z.enabled and z.mode == "client" and not z.connect:
        p.append("publish.zenoh.connect: client mode needs a router (or peer) endpoint to connect to")
    return p


def _datagram_fits(cfg: Config) -> list[str]:
    """At least one landmark must fit one packet (``max_landmarks`` need not: the nearest that fit are sent)."""
    from ..net.fit import MTU_PAYLOAD_BYTES, landmarks_that_fit  # net imports config

    if landmarks_that_fit(cfg.publish.robot_id, cfg.camera.width_px, cfg.camera.height_px) > 0:
        return []
    return [f"publish.robot_id: with {cfg.publish.robot_id!r} and a {cfg.camera.width_px}x{cfg.camera.height_px} "
            f"camera not even one landmark fits the {MTU_PAYLOAD_BYTES:,}-byte limit of one unfragmented packet"]


def _identity_checks(cfg: Config) -> list[str]:
    """Settings of the track-id filter that are each valid but contradict one another."""
    idp, p = cfg.identity, []
    if idp.max_hidden_young_frames > idp.max_hidden_frames:
        p.append(f"identity.max_hidden_young_frames: {idp.max_hidden_young_frames} is more than "
                 f"identity.max_hidden_frames {idp.max_hidden_frames} (a glimpse would outlive a track)")
    if idp.max_dt_s < idp.nominal_dt_s:
        p.append(f"identity.max_dt_s: {idp.max_dt_s:g} s is less than identity.nominal_dt_s {idp.nominal_dt_s:g} s")
    if idp.outlier_range_frac < idp.min_range_sigma_frac:
        p.append(f"identity.outlier_range_frac: {idp.outlier_range_frac:g} is less than identity.min_range_sigma_frac "
                 f"{idp.min_range_sigma_frac:g} (the outlier component must be the wider one)")
    if idp.outlier_bearing_rad < idp.min_bearing_sigma_rad:
        p.append(f"identity.outlier_bearing_rad: {idp.outlier_bearing_rad:g} is less than "
                 f"identity.min_bearing_sigma_rad {idp.min_bearing_sigma_rad:g} (the outlier component must be "
                 "the wider one)")
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
    source = ck.show(str(path), 200)[1:-1]
    try:
        cfg = config_from_mapping(parsed(path, _load_yaml), source)
        if cfg.source.path and not Path(cfg.source.path).is_absolute():  # relative to the file, not the cwd
            resolved = str((Path(path).parent / cfg.source.path).resolve())
            cfg = dataclasses.replace(cfg, source=dataclasses.replace(cfg.source, path=resolved))
    except ConfigError:
        raise
    # The checks above are meant to catch everything; a case they miss is still a problem
    # of this file, never a traceback (at start-up) or a dead daemon (on SIGHUP).
    except (ValueError, TypeError, KeyError, AttributeError, OverflowError, RecursionError, OSError,
            RuntimeError) as exc:
        raise ConfigError([f"cannot use this file: {type(exc).__name__}: {ck.show(str(exc), 200)[1:-1]}"],
                          source) from None
    return cfg


def _load_yaml(path: Union[str, Path]) -> Any:
    from .yaml_safe import load_yaml  # PyYAML: only when the file was not parsed before (.parsed_cache)

    return load_yaml(path)


def config_to_mapping(cfg: Config) -> Dict[str, Any]:
    """The YAML-ready mapping of a config (what ``calibrate`` writes)."""

    def plain(v: Any) -> Any:
        return [plain(x) for x in v] if isinstance(v, tuple) else v

    special: Dict[Tuple[str, str], Callable[[Any], Any]] = {
        ("source", "controls"): lambda v: {k: plain(x) for k, x in v},
        ("publish", "unicast"): lambda v: [f"{h}:{p}" for h, p in v],
    }
    def mapping(name: str, section: Any, checks: Mapping[str, Any]) -> Dict[str, Any]:
        out: Dict[str, Any] = {}
        for key, chk in checks.items():
            value = getattr(section, key)
            if isinstance(chk, ck.Section):
                out[key] = mapping(f"{name}.{key}", value, chk.checks)
            else:
                out[key] = special.get((name, key), plain)(value)
        return out

    return {name: mapping(name, getattr(cfg, name), SCHEMA[name][1]) for name in SCHEMA}


def dump_config(cfg: Config) -> str:
    """The config as YAML text that :func:`load_config` accepts unchanged."""
    import yaml

    return yaml.safe_dump(config_to_mapping(cfg), sort_keys=False, default_flow_style=None)
