"""Pieces shared by the command handlers: config loading, progress, reading lines."""

from __future__ import annotations

import argparse
import math
import sys
from typing import Iterable, Iterator, Optional, TypeVar

from ..config import Config, load_config
from ..net.protocol import LandmarkLike

T = TypeVar("T")


def add_config_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument("--config", metavar="FILE", help="YAML config (default: built-in defaults)")


def config_from_args(args: argparse.Namespace) -> Config:
    return load_config(getattr(args, "config", None))


def progress(items: Iterable[T], total: Optional[int], label: str, enabled: Optional[bool] = None) -> Iterator[T]:
    """Yield ``items`` while drawing a progress bar on stderr when it is a terminal."""
    show = sys.stderr.isatty() if enabled is None else enabled
    n = 0
    for n, item in enumerate(items, 1):
        if show and (n % 5 == 0 or n == total):
            if total:
                done = int(30 * n / total)
                sys.stderr.write(f"\r{label} [{'#' * done}{'.' * (30 - done)}] {n}/{total}")
            else:
                sys.stderr.write(f"\r{label} {n}")
            sys.stderr.flush()
        yield item
    if show and n:
        sys.stderr.write("\n")


def describe(lm: LandmarkLike) -> str:
    """One landmark, seen here or received, as ``0.412 m  +12.3°`` (noted when outside the envelope)."""
    note = "" if lm.in_envelope else " (out of envelope)"
    return f"{lm.range_m:.3f} m  {math.degrees(lm.bearing_rad):+.1f}°{note}"
