"""``photoreal-alt``: the photoreal scenes through another camera and other paint.

``photoreal`` is one guess at the judging renderer's camera (the Pi Camera v1's
lens and ISP). An independent path tracer with its own camera model makes other
choices, each plausible and none ours; this preset draws several of them per
frame on top of a ``photoreal`` (or, one frame in four, ``photoreal-crowd``)
scene, every one from the seed and none moving geometry, so the truth stays
exact (see docs/synth.md, "Another camera"):

- **tone curve**: the sRGB curve or a filmic S-curve instead of a plain gamma;
- **exposure** off by 1–2 stops (an AE metering another way, a bright or dark scene);
- **vignetting** up to 50 % in the corners, **lateral colour** up to ±0.4 % (a
  red/blue fringe of ~1 px at the frame's sides), a small **barrel or pincushion
  distortion** the detector's camera does not know of (a calibration's residual);
- **motion blur** of the whole frame: the observing robot turning (1–8 px);
- **video coding**: chroma in 2×2 blocks and coarse 8×8 transform coding; or
  an **MJPEG stream** at JPEG quality 40–75;
- **glossy paint** with tight specular streaks along the cylinder;
- **paint off ours**: red towards orange or magenta, blue towards cyan or
  violet, less saturated or dirty paint, an off-white (cream, grey) body;
- **colour bleed**: a red or blue wall behind, its light bounced onto the body.
"""

from __future__ import annotations

import colorsys
import dataclasses
from typing import Tuple

import numpy as np

from ..core.types import CameraIntrinsics
from . import sampling as d
from .photoreal import photoreal_scene
from .scene import BLUE_PAINT, RED_PAINT, RGB, WHITE_PAINT, Scene

ALT_PRESET = "photoreal-alt"
ALT_HELP = {ALT_PRESET: "photoreal scenes through another camera: sRGB/filmic tone, +-1-2 stops, "
                        "vignetting, lateral colour, barrel/pincushion, pan blur, video coding or MJPEG, "
                        "glossy streaks, paint hues off ours, colour bleed from red/blue walls"}
DISPLAY_GAMMA = 2.2  # paint hues are turned in display space, where a hue threshold sees them
WALLS: Tuple[RGB, ...] = ((0.55, 0.07, 0.05), (0.62, 0.18, 0.08), (0.06, 0.10, 0.50), (0.10, 0.22, 0.55))


def alt_scene(rng: np.random.Generator, camera: CameraIntrinsics) -> Scene:
    """One ``photoreal-alt`` frame: a photoreal scene, then another camera's and paint's draws."""
    base = photoreal_scene(rng, "photoreal-crowd" if rng.random() < 0.25 else "photoreal", camera)
    return alt_camera(rng, alt_paint(rng, base))


def alt_camera(rng: np.random.Generator, scene: Scene) -> Scene:
    """The scene's imaging with another camera's choices drawn (each on in part of the frames)."""
    im = scene.imaging
    tone = ("gamma", "srgb", "filmic", "filmic")[int(rng.integers(4))]
    gamma = im.gamma if tone != "gamma" else 1.0 / d.uniform(rng, 1.8, 2.6)
    ae_error = im.ae_error
    if rng.random() < 0.4:  # 1-2 stops under or over what the AE wanted (instead of the scene's own AE error)
        ae_error = 2.0 ** (d.uniform(rng, 1.0, 2.0) * (1.0 if rng.random() < 0.5 else -1.0))
    pan = d.uniform(rng, 1.0, 8.0) if rng.random() < 0.3 else 0.0
    barrel = d.uniform(rng, -0.012, 0.0) if rng.random() < 0.5 else 0.0
    video = int(rng.integers(35, 71)) if rng.random() < 0.3 else 0
    if barrel == 0.0 and rng.random() < 0.4:  # a pincushion residual (a longer lens, a calibration the other way)
        barrel = d.uniform(rng, 0.0, 0.008)
    # a camera streaming MJPEG: coarser JPEG than a still's (the video coding wins where both are drawn)
    jpeg = int(rng.integers(40, 76)) if rng.random() < 0.25 else im.jpeg_quality
    imaging = dataclasses.replace(
        im, tone=tone, gamma=gamma, ae_error=ae_error, pan_blur_px=pan, barrel_k1=barrel,
        h264_quality=video, jpeg_quality=jpeg, vignetting=d.uniform(rng, 0.15, 0.5),
        lateral_colour=d.uniform(rng, -1.0, 1.0) * 0.004)
    light = scene.lighting
    if rng.random() < 0.5:  # glossy plastic with tight highlights: streaks along the cylinder
        light = dataclasses.replace(light, gloss=d.uniform(rng, 0.3, 0.8), shininess=d.uniform(rng, 40.0, 250.0),
                                    fresnel=d.uniform(rng, 0.6, 1.0))
    return dataclasses.replace(scene, imaging=imaging, lighting=light)


def alt_paint(rng: np.random.Generator, scene: Scene) -> Scene:
    """Paint off ours (hue turned, less saturated, darker or dirty; an off-white body) and, one
    room in three with a wall, a saturated red or blue wall whose light bleeds onto the body."""
    red = turned(RED_PAINT, d.uniform(rng, -15.0, 15.0), d.uniform(rng, 0.7, 1.0), d.uniform(rng, 0.75, 1.05))
    blue = turned(BLUE_PAINT, d.uniform(rng, -20.0, 20.0), d.uniform(rng, 0.7, 1.0), d.uniform(rng, 0.75, 1.1))
    tint = np.asarray(d.jitter(rng, (1.0, 0.97, 0.88) if rng.random() < 0.5 else (1.0, 1.0, 1.0), 0.03))
    white = tuple(float(v) for v in np.clip(np.asarray(WHITE_PAINT) * tint * d.uniform(rng, 0.7, 1.05), 0, 0.95))
    out = dataclasses.replace(scene, paint=(red, white, blue))  # type: ignore[arg-type]
    if scene.wall_distance_m is not None and rng.random() < 0.33:
        wall = d.jitter(rng, WALLS[int(rng.integers(len(WALLS)))], 0.02)
        out = dataclasses.replace(out, wall_colour=wall, brick_wall=False, local_bounce=True)
    return out


def turned(paint: RGB, hue_deg: float, sat: float, value: float) -> RGB:
    """A linear paint colour with its display-space hue turned by ``hue_deg``, its saturation
    times ``sat`` and its value times ``value`` (a paint of the same name from another maker)."""
    disp = [max(c, 0.0) ** (1.0 / DISPLAY_GAMMA) for c in paint]
    h, s, v = colorsys.rgb_to_hsv(*disp)
    rgb = colorsys.hsv_to_rgb((h + hue_deg / 360.0) % 1.0, min(s * sat, 1.0), min(v * value, 1.0))
    r, g, b = (float(min(max(c, 0.0), 1.0) ** DISPLAY_GAMMA) for c in rgb)
    return (r, g, b)


__all__ = ["ALT_HELP", "ALT_PRESET", "alt_camera", "alt_paint", "alt_scene", "turned"]
