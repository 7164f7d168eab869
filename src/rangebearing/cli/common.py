"""Pieces shared by the command handlers: config and source options, config saving, progress, reading lines.

Command modules import from here, never from each other.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, Dict, Iterable, Iterator, List, Optional, TypeVar, Union

from ..config import Config, SourceConfig, dump_config, load_config
from ..config.schema import MAX_CAMERA_NUM, MAX_FPS
from ..errors import ConfigError, OutputError
from ..net.protocol import LandmarkLike, Reading

if TYPE_CHECKING:
    from ..evaluation.truth import TruthRow
    from ..net.zenoh_transport import ZenohSettings

T = TypeVar("T")
DEFAULT_ZENOH_LISTEN = "tcp/127.0.0.1:7447"  # a controller on this machine; tcp/0.0.0.0:7447 for a lab


def add_config_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument("--config", metavar="FILE", help="YAML config (default: built-in defaults)")


def config_from_args(args: argparse.Namespace) -> Config:
    return load_config(getattr(args, "config", None))


def add_quiet_arg(p: argparse.ArgumentParser, what: str = "the progress bar") -> None:
    p.add_argument("-q", "--quiet", action="store_true", help=f"quiet: no {what}")


def progress(
    items: Iterable[T], total: Optional[int], label: str, enabled: Optional[bool] = None, unit: str = "frame"
) -> Iterator[T]:
    """Yield ``items`` while tqdm draws a progress bar on stderr, only when stderr is a terminal.

    ``enabled=False`` (``-q``) hides it; ``None`` shows it on a terminal only,
    so piped or logged output stays clean.
    """
    show = sys.stderr.isatty() if enabled is None else enabled
    if not show:
        yield from items
        return
    from tqdm import tqdm  # imported here: only a terminal needs it

    with tqdm(items, total=total, desc=label, unit=unit, file=sys.stderr, dynamic_ncols=True, leave=True) as bar:
        yield from bar


def quiet_or_auto(args: argparse.Namespace) -> Optional[bool]:
    """``enabled`` for :func:`progress`: False with ``-q``, else decided by the terminal."""
    return False if getattr(args, "quiet", False) else None


def write_atomic(path: Union[str, Path], text: str) -> Optional[Path]:
    """Write ``text`` to ``path`` atomically; an existing file is kept as ``path.bak``, returned.

    The text goes to a temporary file in the same folder, flushed to disk, then
    replaces ``path`` in one rename, so a crash leaves the old file or the new
    one, never half of one.
    """
    out = Path(path)
    backup = None
    if out.exists():
        backup = out.with_name(out.name + ".bak")
        import shutil  # not on `run`'s start-up path (it brings bz2 and lzma)

        try:
            shutil.copy2(out, backup)
        except OSError as exc:
            raise OutputError(f"cannot keep {out} as {backup}: {exc.strerror or exc}") from None
    from .outputs import write_bytes_atomic  # not on `run`'s start-up path

    write_bytes_atomic(out, text.encode("utf-8"), durable=True)
    return backup


def save_config(cfg: Config, path: Union[str, Path], header: str) -> None:
    """Write a complete config (``header`` as comment lines on top) atomically, and say so on stderr."""
    comment = "".join(f"# {line}\n" for line in header.splitlines())
    backup = write_atomic(path, comment + dump_config(cfg))
    note = f" (the old file is {backup})" if backup else ""
    print(f"wrote {path}{note}", file=sys.stderr)


def describe(lm: LandmarkLike) -> str:
    """One landmark, seen here or received: ``id 7: 0.412 m ±2.3 mm  +12.3° ±0.03°  -0.123 m/s  +31.1°/s``.

    The track id, the sigmas and the rates appear when the landmark carries
    them (an older sender sends none: ``0.412 m  +12.3°``); partly hidden and
    out-of-envelope landmarks are noted.
    """
    tid = getattr(lm, "track_id", None)
    rs, bs = getattr(lm, "range_sigma_m", None), getattr(lm, "bearing_sigma_rad", None)
    rr, br = getattr(lm, "range_rate_mps", None), getattr(lm, "bearing_rate_radps", None)
    vis = getattr(lm, "visible", None)
    parts = [f"id {tid}: " if tid is not None and tid >= 0 else ""]
    parts.append(f"{lm.range_m:.3f} m" + (f" ±{1000 * rs:.1f} mm" if rs is not None else ""))
    parts.append(f"  {math.degrees(lm.bearing_rad):+.1f}°" + (f" ±{math.degrees(bs):.2f}°" if bs is not None else ""))
    if rr is not None:
        parts.append(f"  {rr:+.3f} m/s")
    if br is not None:
        parts.append(f"  {math.degrees(br):+.1f}°/s")
    if vis is not None and vis < 0.995:
        parts.append(f" ({100 * vis:.0f} % visible)")
    if not lm.in_envelope:
        parts.append(" (out of envelope)")
    return "".join(parts)


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
    if spec is not None and not spec.strip():
        raise ConfigError(["--source: empty: name a source (picamera2[:N], opencv:DEVICE, synthetic, or a folder "
                           "of images or a video file)"], "command line")
    if spec:
        kind, _, rest = spec.partition(":")
        if kind == "picamera2":
            if rest and not (rest.isdigit() and int(rest) <= MAX_CAMERA_NUM):
                raise ConfigError([f"--source: {spec!r}: the camera number must be an integer from 0 to "
                                   f"{MAX_CAMERA_NUM}"], "command line")
            src = dataclasses.replace(src, kind="picamera2", camera_num=int(rest) if rest else src.camera_num)
        elif kind == "opencv":
            if not rest:  # "opencv:" meaning device 0 silently surprised people: say which one
                raise ConfigError([f"--source: {spec!r}: name the device, e.g. opencv:0 or opencv:/dev/video0"],
                                  "command line")
            src = dataclasses.replace(src, kind="opencv", device=rest)
        elif kind == "synthetic":
            src = dataclasses.replace(src, kind="synthetic")
        else:
            path = rest if kind == "recorded" else spec
            if path and not Path(path).exists():  # "--source webcam" is not a folder of frames
                raise ConfigError([f"--source: {spec!r} is neither a source kind (picamera2[:N], opencv:DEVICE, "
                                   "synthetic) nor an existing folder of images or video file"], "command line")
            src = dataclasses.replace(src, kind="recorded", path=path)
    if fps is not None:
        if not 0.0 <= fps <= MAX_FPS:  # NaN too; the config's own bound (source.fps)
            raise ConfigError([f"--fps: must be a number from 0 to {MAX_FPS:g}, got {fps:g}"], "command line")
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


def aligned_truth(frames_path: Union[str, Path], truth_path: Union[str, Path]) -> Dict[str, List[TruthRow]]:
    """The truth CSV keyed by the frames' own names (see :func:`~rangebearing.evaluation.truth.align_truth`).

    A video's (and an MCAP file's) frames are named by their 0-based index, as ``replay`` prints them:
    ``0``, ``1``, …; MCAP truth may also name a frame by its capture timestamp in integer Unix ns.
    """
    from ..evaluation.truth import align_truth, read_truth
    from ..sources.mcap_frames import is_mcap_file
    from ..sources.recorded import count_recorded, list_images

    truth = read_truth(truth_path)
    path = Path(frames_path)
    if path.is_file() and is_mcap_file(path):  # MCAP truth may name frames by capture time (ns)
        from ..evaluation.truth import key_by_position
        from ..sources.mcap_frames import frame_times_ns

        truth = key_by_position(truth, frame_times_ns(path))
    if path.is_dir():
        count_recorded(path)  # an empty directory is named as such, not as truth that matches no frame
        names = [p.name for p in list_images(path)]
    else:
        n = count_recorded(path)
        if n is None:  # the container does not say: any index a truth row names may exist
            n = 1 + max((int(k) for k in truth if k.strip().isdigit()), default=-1)
        names = [str(i) for i in range(n)]
    return align_truth(truth, names, str(truth_path))


def add_zenoh_args(p: argparse.ArgumentParser, default_listen: Optional[str]) -> None:
    """The options that say how to join a Zenoh network (shared with ``listen --zenoh``)."""
    p.add_argument("--mode", choices=("peer", "client"), default="peer", help="Zenoh session mode (default peer)")
    p.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                   help="dial a peer or router, e.g. tcp/10.0.0.1:7447 (repeatable)")
    p.add_argument("--listen", action="append", default=[], metavar="ENDPOINT",
                   help=f"accept peers on this endpoint (repeatable; default {default_listen or 'none'}; "
                        "tcp/0.0.0.0:7447 hears the whole network)")
    p.add_argument("--scout", action="store_true",
                   help="find peers by multicast scouting on the local network (off by default)")
    p.add_argument("--key", default="rangebearing/*/readings",
                   help="key expression to subscribe to (default rangebearing/*/readings: every robot)")


def settings_from_args(args: argparse.Namespace, default_listen: Optional[str]) -> ZenohSettings:
    """Zenoh settings from the command line; with --connect and no --listen, Zenoh's own default listen."""
    quiet = default_listen and args.mode == "peer" and not args.connect
    listen = tuple(args.listen) or ((default_listen,) if quiet else ())
    from ..net.zenoh_transport import ZenohSettings  # the Zenoh commands only

    return ZenohSettings(mode=args.mode, connect=tuple(args.connect), listen=listen,
                         scouting_multicast=bool(args.scout))


def positive(kind: type, unit: str = "", most: float = math.inf) -> Any:
    """An argparse ``type``: a finite number of ``kind`` above 0 and at most ``most`` (``unit`` names it)."""

    def parse(text: str) -> Any:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a {unit or kind.__name__}") from None
        if not value > 0 or (isinstance(value, float) and not math.isfinite(value)):
            raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
        if value > most:  # a timeout of 1e300 s overflowed time_t (an OverflowError, "a bug?")
            raise argparse.ArgumentTypeError(f"must be at most {most:g}, got {text}")
        return value

    return parse
