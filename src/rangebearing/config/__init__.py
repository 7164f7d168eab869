"""The application configuration: load and validate once, at start-up and on SIGHUP.

>>> from rangebearing.config import load_config
>>> cfg = load_config(None)          # built-in defaults
>>> cfg.pipeline                     # what the core needs  # doctest: +SKIP
"""

from __future__ import annotations

from .load import check, config_from_mapping, config_to_mapping, dump_config, load_config
from .schema import DEFAULT_PORT, SCHEMA, SOURCES, Config, DaemonConfig, PublishConfig, SourceConfig, ZenohConfig

__all__ = [
    "DEFAULT_PORT",
    "SCHEMA",
    "SOURCES",
    "Config",
    "DaemonConfig",
    "PublishConfig",
    "SourceConfig",
    "ZenohConfig",
    "check",
    "config_from_mapping",
    "config_to_mapping",
    "dump_config",
    "load_config",
]
