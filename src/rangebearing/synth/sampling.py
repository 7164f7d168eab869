"""Random draws shared by the scene presets: rooms, light, sensor, landmark placement."""

from __future__ import annotations

import dataclasses
import math
from typing import Callable, Dict, Optional, Tuple

import numpy as np

from ..core.types import CameraIntrinsics
from ..errors import SceneError
from .camera import inside_image, landmark_bbox_px
from .scene import DEFAULT_BASE_HEIGHT_M, RGB, Imaging, LandmarkPose, Lighting, Scene

MARGIN_PX = 3.0
BASE_EXPOSURE = 1.25

FLOOR_TINTS: Dict[str, RGB] = {
    "warm wood": (0.55, 0.38, 0.24),
    "cool grey": (0.50, 0.53, 0.58),
    "greenish": (0.40, 0.50, 0.36),
    "beige": (0.66, 0.60, 0.50),
    "grey": (0.58, 0.58, 0.58),
}
WALL_TINTS: Dict[str, RGB] = {
    "off-white": (0.80, 0.78, 0.74),
    "blue-grey": (0.62, 0.66, 0.72),
    "pale green": (0.64, 0.70, 0.62),
    "warm beige": (0.76, 0.68, 0.58),
    "grey": (0.70, 0.70, 0.70),
}
LIGHTS = ("normal", "dim", "bright", "warm", "cool")


def uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(rng.uniform(lo, hi))


def log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    """Uniform in log r: as many draws in 0.15–0.3 m as in 1–2 m."""
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def jitter(rng: np.random.Generator, rgb: RGB, amount: float = 0.03) -> RGB:
    c = np.clip(np.asarray(rgb) + rng.uniform(-amount, amount, 3), 0.0, 1.0)
    return (float(c[0]), float(c[1]), float(c[2]))


def pick(rng: np.random.Generator, table: Dict[str, RGB]) -> RGB:
    return table[list(table)[int(rng.integers(len(table)))]]


def neutral_room(rng: np.random.Generator) -> Dict[str, RGB]:
    g, w = uniform(rng, 0.55, 0.75), uniform(rng, 0.72, 0.85)
    return {"floor_colour": jitter(rng, (g, g, g), 0.015),
            "wall_colour": jitter(rng, (w, w, w), 0.015)}


def tinted_room(rng: np.random.Generator) -> Dict[str, RGB]:
    return {"floor_colour": jitter(rng, pick(rng, FLOOR_TINTS)),
            "wall_colour": jitter(rng, pick(rng, WALL_TINTS))}


def lighting(rng: np.random.Generator, kind: str = "normal") -> Lighting:
    """One of :data:`LIGHTS`: normal, dim (×0.3–0.5), bright (×1.6–2.2, clips), warm or cool WB."""
    direction = (-0.35 + uniform(rng, -0.4, 0.4), 0.75 + uniform(rng, -0.2, 0.2),
                 -0.55 + uniform(rng, -0.3, 0.3))
    exposure = BASE_EXPOSURE * uniform(rng, 0.9, 1.1)
    gains = [1.0 + uniform(rng, -0.03, 0.03) for _ in range(3)]
    if kind == "dim":
        exposure = BASE_EXPOSURE * uniform(rng, 0.3, 0.5)
    elif kind == "bright":
        exposure = BASE_EXPOSURE * uniform(rng, 1.6, 2.2)
    elif kind in ("warm", "cool"):
        up, down = 1.0 + uniform(rng, 0.15, 0.25), 1.0 - uniform(rng, 0.15, 0.25)
        gains[0], gains[2] = (up, down) if kind == "warm" else (down, up)
    elif kind != "normal":
        raise ValueError(f"unknown lighting {kind!r}")
    return Lighting(direction=direction, ambient=uniform(rng, 0.35, 0.5), exposure=exposure,
                    wb_gains=(gains[0], gains[1], gains[2]))


def imaging(rng: np.random.Generator, noise: float = 1.0, blur: Tuple[float, float] = (0.3, 0.8)
            ) -> Imaging:
    """Sensor draw; ``noise`` scales read and shot noise (1 = mild)."""
    return Imaging(blur_sigma_px=uniform(rng, *blur),
                   read_noise=noise * uniform(rng, 0.002, 0.005),
                   shot_noise=noise * uniform(rng, 0.0003, 0.001))


def bearing_limits(camera: CameraIntrinsics, range_m: float, radius_m: float,
                   margin_px: float = MARGIN_PX) -> Tuple[float, float]:
    """Bearings at which a cylinder of ``radius_m`` at ``range_m`` lies wholly in the
    image ``margin_px`` from its sides (pinhole; its half-width is asin(radius/range))."""
    half = math.asin(min(1.0, radius_m / range_m))
    left = math.atan((camera.cx_px + 0.5 - margin_px) / camera.fx_px) - half
    right = math.atan((camera.width_px - 0.5 - margin_px - camera.cx_px) / camera.fx_px) - half
    return -right, left


def in_view(scene: Scene, lm: LandmarkPose, margin_px: float = MARGIN_PX) -> bool:
    """Whether the whole landmark (both bands) lies inside the frame."""
    return inside_image(scene.camera, landmark_bbox_px(scene, lm), margin_px)


def draw_landmark(rng: np.random.Generator, scene: Scene,
                  draw_range: Callable[[], float], base_spread_m: float = 0.0,
                  accept: Optional[Callable[[LandmarkPose], bool]] = None,
                  attempts: int = 200) -> Optional[LandmarkPose]:
    """A landmark wholly in view of ``scene``'s camera (and accepted), or None."""
    for _ in range(attempts):
        r = draw_range()
        lo, hi = bearing_limits(scene.camera, r, scene.geometry.radius_m)
        if lo >= hi:
            continue
        base = DEFAULT_BASE_HEIGHT_M + uniform(rng, -1.0, 1.0) * base_spread_m
        lm = LandmarkPose(r, uniform(rng, lo, hi), base)
        if in_view(scene, lm) and (accept is None or accept(lm)):
            return lm
    return None


def give_up(preset: str, camera: CameraIntrinsics) -> SceneError:
    return SceneError([f"preset {preset!r}: cannot place landmarks wholly in view of a "
                        f"{camera.width_px}x{camera.height_px} camera"], "synth")


def with_wall_behind(scene: Scene, rng: np.random.Generator, lo: float, hi: float,
                     open_room_p: float = 0.0) -> Scene:
    """Put the back wall ``lo``–``hi`` m behind the farthest robot (or none at all)."""
    if rng.random() < open_room_p:
        return dataclasses.replace(scene, wall_distance_m=None)
    far = max([lm.z_m for lm in scene.landmarks] + [0.0]) + scene.robot_radius_m
    return dataclasses.replace(scene, wall_distance_m=far + uniform(rng, lo, hi))
