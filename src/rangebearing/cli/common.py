"""Pieces shared by the command handlers: config and source options, progress, reading lines.

Command modules import from here, never from each other.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from typing import Iterable, Iterator, Optional, TypeVar

from ..config import Config, SourceConfig, load_config
from ..errors import ConfigError
from ..net.protocol import LandmarkLike, Reading

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


def add_source_args(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--source",
        metavar="SPEC",
        help="override the config's source: picamera2[:N], opencv:DEVICE (index, /dev/videoN, file, URL), "
        "synthetic, or a directory of images / video file (recorded)",
    )
    p.add_argument("--fps", type=float, help="frame rate (recorded frames: pace; 0 = as fast as possible)")
    p.add_argument("--loop", action="store_true", help="recorded frames: start again at the end")


def source_from_args(args: argparse.Namespace, base: SourceConfig) -> Optional[SourceConfig]:
    """The source named on the command line, or ``None`` when none was given."""
    spec, fps, loop = getattr(args, "source", None), getattr(args, "fps", None), getattr(args, "loop", False)
    if spec is None and fps is None and not loop:
        return None
    src = base
    if spec:
        kind, _, rest = spec.partition(":")
        if kind == "picamera2":
            if rest and not rest.isdigit():
                raise ConfigError([f"--source: {spec!r}: the camera number must be an integer"], "command line")
            src = dataclasses.replace(src, kind="picamera2", camera_num=int(rest) if rest else src.camera_num)
        elif kind == "opencv":
            src = dataclasses.replace(src, kind="opencv", device=rest or src.device)
        elif kind == "synthetic":
            src = dataclasses.replace(src, kind="synthetic")
        else:
            src = dataclasses.replace(src, kind="recorded", path=rest if kind == "recorded" else spec)
    if fps is not None:
        if fps < 0:
            raise ConfigError(["--fps: must be >= 0"], "command line")
        src = dataclasses.replace(src, fps=fps)
    if loop:
        src = dataclasses.replace(src, loop=True)
    return src


def printable(text: str) -> str:
    """``text`` safe for a terminal: control characters, lone surrogates and other
    non-printables (and the backslash itself) written as ``\\x1b``, ``\\u202e``, ``\\\\``.

    Robot ids come from the network: raw, a newline would fake a reading line and an
    ANSI escape would drive the terminal.
    """
    if text.isprintable() and "\\" not in text:
        return text
    out = []
    for ch in text:
        code = ord(ch)
        if ch == "\\":
            out.append("\\\\")
        elif ch.isprintable():
            out.append(ch)
        elif code < 0x100:
            out.append(f"\\x{code:02x}")
        elif code < 0x10000:
            out.append(f"\\u{code:04x}")
        else:
            out.append(f"\\U{code:08x}")
    return "".join(out)


def format_reading(reading: Reading) -> str:
    """One human-readable line for one reading (the robot id escaped by :func:`printable`)."""
    n = len(reading.landmarks)
    head = f"{printable(reading.robot)} #{reading.seq} t={reading.t:.3f}  {n} landmark{'' if n == 1 else 's'}"
    parts = [describe(lm) for lm in reading.landmarks]
    line = f"{head}: {' | '.join(parts)}" if parts else head
    extras = []
    if reading.fps is not None:
        extras.append(f"{reading.fps:.1f} fps")
    if reading.dropped:
        extras.append(f"{reading.dropped} dropped")
    if reading.omitted:
        extras.append(f"{reading.omitted} more not sent: datagram full")
    return f"{line}  [{', '.join(extras)}]" if extras else line
