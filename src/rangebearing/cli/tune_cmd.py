"""``rangebearing tune``: lock exposure and white balance, derive the colour thresholds from a landmark."""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from ..config import Config, check
from ..core.color import apply_gains, grey_world_gains, to_hsv
from ..core.colour_tune import ColourRanges, band_core, derive_ranges, search_ladder
from ..core.detect import downscale
from ..core.pipeline import Pipeline
from ..core.types import Landmark
from ..errors import CalibrationError, FrameError
from ..sources.base import FrameSource
from ..sources.factory import open_source
from .common import add_config_arg, add_source_args, config_from_args, save_config, source_from_args
from .outputs import check_config_out

LATENCY_FRAMES = 6  # frames to discard after set_controls (libcamera applies controls a few frames on)


def register(sub: Any) -> None:
    p = sub.add_parser(
        "tune",
        help="lock exposure and white balance and fit the colour thresholds to a landmark in view",
        description="With one landmark in view (0.3-0.6 m straight ahead is best): let the camera's auto "
        "exposure and white balance settle, lock them at the values they reached (Picamera2 AeEnable/AwbEnable "
        "off with the measured ExposureTime, AnalogueGain and ColourGains), find the landmark with the "
        "current thresholds (loosened step by step if needed), derive red and blue hue ranges and the "
        "saturation and value minimums from its band pixels with margins, check them, and write a complete "
        "config (an existing file is kept as FILE.bak).",
    )
    p.add_argument("--out", required=True, metavar="FILE", help="where to write the tuned config (YAML)")
    p.add_argument("--frames", type=int, default=10, metavar="N", help="frames to measure (default 10)")
    p.add_argument("--settle", type=int, default=30, metavar="N",
                   help="frames to let auto exposure and white balance settle first (default 30)")
    add_config_arg(p)
    add_source_args(p)
    p.set_defaults(func=run)


def read_frames(source: FrameSource, n: int) -> List[np.ndarray]:
    """Up to ``n`` frames (fewer at the end of a recording); bad frames are skipped, at most ``n`` of them."""
    out: List[np.ndarray] = []
    bad = 0
    while len(out) < n:
        try:
            frame = source.read()
        except FrameError as exc:
            bad += 1
            if bad > n:
                raise CalibrationError(f"{bad} bad frames in a row from the source: {exc}") from None
            continue
        if frame is None:
            break
        out.append(frame.image)
    return out


def lock_controls(metadata: Dict[str, Any]) -> Dict[str, Any]:
    """Controls that freeze AE and AWB at what the metadata reports (picamera2's examples/controls.py)."""
    missing = [k for k in ("ExposureTime", "AnalogueGain", "ColourGains") if k not in metadata]
    if missing:
        raise CalibrationError(f"the camera does not report {', '.join(missing)} in its metadata")
    r, b = metadata["ColourGains"]
    return {
        "AeEnable": False,
        "ExposureTime": int(metadata["ExposureTime"]),
        "AnalogueGain": round(float(metadata["AnalogueGain"]), 4),
        "AwbEnable": False,
        "ColourGains": (round(float(r), 4), round(float(b), 4)),
    }


def _with_thresholds(cfg: Config, red_hue: Any, blue_hue: Any, s_min: int, v_min: int) -> Config:
    det = dataclasses.replace(cfg.detection, red_hue=tuple(red_hue), blue_hue=tuple(blue_hue), s_min=s_min,
                              v_min=v_min)
    return dataclasses.replace(cfg, detection=det)


def find_landmark(frames: List[np.ndarray], cfg: Config) -> Tuple[List[Optional[Landmark]], int]:
    """The nearest landmark in each frame with the loosest-needed step of :func:`search_ladder`, and that step."""
    det = cfg.detection
    for step, (red, blue, s, v) in enumerate(search_ladder(det.red_hue, det.blue_hue, det.s_min, det.v_min)):
        pipe = Pipeline(_with_thresholds(cfg, red, blue, s, v).pipeline, track=False)
        found = [next(iter(pipe.process(f).landmarks), None) for f in frames]
        if sum(lm is not None for lm in found) * 2 > len(frames):
            return found, step
    raise CalibrationError(
        "no landmark found, even with loosened thresholds: put one 0.3-0.6 m in front of the camera, in the light"
    )


def band_pixels(frames: List[np.ndarray], found: List[Optional[Landmark]], cfg: Config) -> Tuple[np.ndarray, ...]:
    """HSV pixels of every found landmark's red and blue band cores, as the detector sees them."""
    ratio = cfg.landmark.band_height_m / cfg.landmark.band_spacing_m
    reds, blues = [], []
    for image, lm in zip(frames, found):
        if lm is None:
            continue
        if cfg.detection.white_balance == "grey_world":
            image = apply_gains(image, grey_world_gains(downscale(image, cfg.detection.downscale)))
        hsv = to_hsv(image)
        band_h = lm.l_px * ratio
        reds.append(band_core(hsv, lm.red_xy_px, lm.width_px, band_h))
        blues.append(band_core(hsv, lm.blue_xy_px, lm.width_px, band_h))
    return np.concatenate(reds), np.concatenate(blues)


def exposure_warnings(red: np.ndarray, blue: np.ndarray) -> List[str]:
    """Bands that clip or sit in the dark make poor thresholds; say so."""
    out = []
    for name, px in (("red", red), ("blue", blue)):
        if np.mean(px[:, 2] >= 250) > 0.05:
            out.append(f"the {name} band clips (value 250+ in {100 * np.mean(px[:, 2] >= 250):.0f} % of its pixels)")
        if np.median(px[:, 2]) < 40:
            out.append(f"the {name} band is dark (median value {np.median(px[:, 2]):.0f} of 255)")
    return out


def describe(r: ColourRanges) -> str:
    return (f"red hue {list(r.red_hue)}, blue hue {list(r.blue_hue)}, s_min {r.s_min}, v_min {r.v_min} "
            f"(from {r.red_pixels} red and {r.blue_pixels} blue pixels)")


def run(args: argparse.Namespace) -> int:
    if args.frames < 1 or args.settle < 0:
        raise CalibrationError("--frames must be at least 1 and --settle at least 0")
    cfg = config_from_args(args)
    src_cfg = source_from_args(args, cfg.source) or cfg.source
    cfg = dataclasses.replace(cfg, source=src_cfg)
    check(cfg)
    # fail now, not after the frames: a writable file (an existing one is kept as .bak), never the recording
    check_config_out(args.out, "--out", src_cfg.path if src_cfg.kind == "recorded" else None)
    source = open_source(src_cfg, cfg.camera)
    locked: Dict[str, Any] = {}
    try:
        if callable(getattr(source, "set_controls", None)):
            read_frames(source, max(1, args.settle))
            metadata = source.metadata  # type: ignore[attr-defined]
            locked = lock_controls(metadata)
            if metadata.get("ScalerCrop"):
                crop = list(metadata["ScalerCrop"])
                print(f"the frames show the sensor's {crop} (ScalerCrop): with camera.model, "
                      f"set camera.scaler_crop: {crop}")
            source.set_controls(locked)  # type: ignore[attr-defined]
            read_frames(source, LATENCY_FRAMES)
            print("locked: " + ", ".join(f"{k} {v}" for k, v in locked.items()))
        else:
            print(f"source {src_cfg.kind!r} has no exposure controls: only the colour thresholds are tuned",
                  file=sys.stderr)
        frames = read_frames(source, args.frames)
    finally:
        source.close()
    if not frames:
        raise CalibrationError("the source gave no frames")
    if locked:  # the camera's white balance is fixed now; a software one would drift with the scene again
        cfg = dataclasses.replace(cfg, detection=dataclasses.replace(cfg.detection, white_balance="none"))
    found, step = find_landmark(frames, cfg)
    if step:
        print(f"the current thresholds miss the landmark; found it with loosened ones (step {step})")
    red, blue = band_pixels(frames, found, cfg)
    for w in exposure_warnings(red, blue):
        print(f"warning: {w}", file=sys.stderr)
    ranges = derive_ranges(red, blue)
    print("thresholds: " + describe(ranges))
    tuned = _with_thresholds(cfg, ranges.red_hue, ranges.blue_hue, ranges.s_min, ranges.v_min)
    pipe = Pipeline(tuned.pipeline, track=False)
    seen = [next(iter(pipe.process(f).landmarks), None) for f in frames]
    hits = [lm for lm in seen if lm is not None]
    if len(hits) < len(frames):
        raise CalibrationError(f"the derived thresholds find the landmark in {len(hits)} of {len(frames)} frames "
                               "only; nothing written (is the landmark steady and well lit?)")
    r = np.mean([lm.range_m for lm in hits])
    b = math.degrees(np.mean([lm.bearing_rad for lm in hits]))
    print(f"check: landmark found in all {len(frames)} frames at {r:.3f} m, {b:+.1f}°")
    controls = dict(src_cfg.controls)
    controls.update(locked)
    tuned = dataclasses.replace(tuned, source=dataclasses.replace(src_cfg, controls=tuple(controls.items())))
    save_config(tuned, args.out, "rangebearing config written by 'rangebearing tune'\n" + describe(ranges))
    return 0
