"""Rooms, light and camera for the newer presets (the original ones keep :mod:`.sampling`).

Light kinds (:data:`LIGHT_KINDS`): ``normal``; ``dim`` (a tenth of the light:
the auto exposure runs out of gain, noise grows); ``bright`` (hard light, an
AE loop over-shooting: clipped bands and body); ``warm`` (tungsten, white
balance only partly corrected); ``cool`` (shade, fluorescent); ``coloured``
(a saturated LED light from one side); ``spotlit`` (a spotlight aimed at one
robot, glossy highlights that clip); ``backlit`` (a bright window behind the
robots, the auto exposure darkening everything else, veiling glare).

Every one runs the camera of :mod:`.sensor`: auto exposure, Bayer mosaic,
noise growing with gain, vignetting. Rooms have textured floors and walls, and
now and then a strongly coloured floor (a navy carpet) or wall.
"""

from __future__ import annotations

import colorsys
import dataclasses
import math
from typing import Tuple

import numpy as np

from ..core.types import CameraIntrinsics
from . import sampling as d
from .scene import RGB, Imaging, Lighting, Poster, Scene, Spot

LIGHT_KINDS = ("normal", "dim", "bright", "warm", "cool", "coloured", "spotlit", "backlit")
EVERYDAY = ("normal", "normal", "warm", "cool", "dim", "bright")


def everyday(rng: np.random.Generator) -> str:
    """A light kind for scenes whose question is not the light."""
    return EVERYDAY[int(rng.integers(len(EVERYDAY)))]


def any_light(rng: np.random.Generator) -> str:
    """Any of :data:`LIGHT_KINDS`."""
    return LIGHT_KINDS[int(rng.integers(len(LIGHT_KINDS)))]


def _scaled(rgb: RGB, k: float) -> RGB:
    return (rgb[0] * k, rgb[1] * k, rgb[2] * k)


def _balance(light: RGB, correct: float) -> RGB:
    """White-balance gains that undo ``correct`` (0–1) of a light's tint, green = 1."""
    g = [(light[1] / c) ** correct for c in light]
    return (g[0], 1.0, g[2])


def lighting(rng: np.random.Generator, kind: str) -> Lighting:
    """The light of one kind (spots and windows are added by :func:`finish`)."""
    u = lambda lo, hi: d.uniform(rng, lo, hi)  # noqa: E731
    direction = (u(-0.8, 0.8), u(0.4, 1.0), u(-0.9, 0.2))
    ambient = u(0.3, 0.5)
    colour: RGB = d.jitter(rng, (1.0, 1.0, 1.0), 0.03)
    amb_colour: RGB = (1.0, 1.0, 1.0)
    gloss = u(0.03, 0.12)
    if kind == "dim":
        k = u(0.06, 0.2)
        colour, amb_colour = _scaled(colour, k), _scaled(amb_colour, k)
    elif kind == "bright":
        ambient = u(0.15, 0.3)
        colour = _scaled(colour, u(1.5, 3.0))
    elif kind == "warm":
        colour = (1.0, u(0.72, 0.85), u(0.45, 0.62))
        amb_colour = colour
    elif kind == "cool":
        colour = (u(0.72, 0.85), u(0.88, 0.95), 1.0)
        amb_colour = colour
    elif kind == "coloured":
        hue = (0.0, 0.08, 0.33, 0.5, 0.62, 0.8, 0.9)[int(rng.integers(7))]
        tint = colorsys.hsv_to_rgb(hue, 1.0, 1.0)
        mix = u(0.3, 0.7)
        colour = tuple(1.0 - mix + mix * c for c in tint)  # type: ignore[assignment]
        ambient = u(0.25, 0.4)
    elif kind == "spotlit":
        colour = _scaled(colour, u(0.3, 0.7))
        gloss = u(0.15, 0.4)
    elif kind == "backlit":
        ambient = u(0.4, 0.6)
    elif kind != "normal":
        raise ValueError(f"unknown light {kind!r}")
    correct = u(0.5, 0.9) if kind in ("warm", "cool", "coloured") else 1.0
    wb = _balance(colour, correct) if kind in ("warm", "cool", "coloured") else (1.0, 1.0, 1.0)
    wb = (wb[0] * u(0.97, 1.03), 1.0, wb[2] * u(0.97, 1.03))
    return Lighting(direction=direction, ambient=ambient, wb_gains=wb, colour=colour,
                    ambient_colour=amb_colour, gloss=gloss, shininess=u(30.0, 120.0))


def imaging(rng: np.random.Generator, kind: str) -> Imaging:
    """The auto-exposed Bayer camera; a settled loop is within ~12 % of its target."""
    err = math.exp(rng.normal(0.0, 0.12))
    if kind == "bright":
        err *= d.uniform(rng, 1.3, 2.0)
    glare = d.uniform(rng, 0.02, 0.05) if kind == "backlit" else d.uniform(rng, 0.003, 0.012)
    return Imaging(blur_sigma_px=d.uniform(rng, 0.3, 0.9), read_noise=d.uniform(rng, 0.002, 0.005),
                   shot_noise=d.uniform(rng, 0.0003, 0.001), auto_exposure=True,
                   ae_target=d.uniform(rng, 0.14, 0.2), ae_error=err, bayer=True, glare=glare,
                   edge_supersample=2, vignetting=d.uniform(rng, 0.1, 0.35))


FLOORS = {
    "navy carpet": (0.045, 0.06, 0.19),  # the carpet that pulled grey-world balance to blue
    "red carpet": (0.30, 0.05, 0.05),
    "dark wood": (0.22, 0.12, 0.06),
    "black rubber": (0.05, 0.05, 0.05),
}
WALLS = {
    "red brick": (0.42, 0.14, 0.09),
    "blue paint": (0.16, 0.24, 0.50),
    "white": (0.86, 0.86, 0.84),
}


def room(rng: np.random.Generator) -> dict:
    """Floor and wall colours and textures: tinted, neutral, and now and then strongly coloured."""
    out = d.tinted_room(rng) if rng.random() < 0.6 else d.neutral_room(rng)
    if rng.random() < 0.2:
        out["floor_colour"] = d.jitter(rng, d.pick(rng, FLOORS), 0.015)
    if rng.random() < 0.12:
        out["wall_colour"] = d.jitter(rng, d.pick(rng, WALLS), 0.02)
    out.update(floor_texture=d.uniform(rng, 0.03, 0.15), wall_texture=d.uniform(rng, 0.0, 0.05),
               texture_seed=int(rng.integers(2**31)))
    return out


def base_scene(rng: np.random.Generator, camera: CameraIntrinsics, kind: str,
               camera_height: Tuple[float, float] = (0.10, 0.10)) -> Scene:
    """A room (see :func:`room`), light of ``kind`` and the camera; no robots yet."""
    walls_floor = room(rng)
    h = camera_height[0] if camera_height[0] == camera_height[1] else d.uniform(rng, *camera_height)
    return Scene(camera=camera, camera_height_m=h, lighting=lighting(rng, kind),
                 imaging=imaging(rng, kind), **walls_floor)


def _spot(rng: np.random.Generator, scene: Scene) -> Spot:
    lm = scene.landmarks[int(rng.integers(len(scene.landmarks)))]
    centre = lm.base_height_m + scene.geometry.height_m / 2
    ang = d.uniform(rng, 0.0, 2 * math.pi)
    reach, up = d.uniform(rng, 0.15, 0.6), d.uniform(rng, 0.3, 0.9)
    pos = (lm.x_m + reach * math.cos(ang), centre + up, lm.z_m + reach * math.sin(ang))
    dist2 = reach * reach + up * up
    strength = d.uniform(rng, 2.5, 8.0) * (1.0 - scene.lighting.ambient)
    return Spot(pos, (lm.x_m, centre, lm.z_m), strength * dist2, d.jitter(rng, (1.0, 0.97, 0.9), 0.03),
                d.uniform(rng, 6.0, 18.0), d.uniform(rng, 1.0, 5.0))


def finish(rng: np.random.Generator, scene: Scene, kind: str) -> Scene:
    """Add what depends on where the robots stand: the spotlight, the window."""
    if kind == "spotlit" and scene.landmarks:
        spots = tuple(_spot(rng, scene) for _ in range(int(rng.integers(1, 3))))
        return dataclasses.replace(scene, lighting=dataclasses.replace(scene.lighting, spots=spots))
    if kind == "backlit":
        glow = d.uniform(rng, 2.0, 8.0)
        sky: RGB = d.jitter(rng, (0.95, 0.98, 1.0), 0.02)
        if scene.wall_distance_m is None:
            return dataclasses.replace(scene, background_colour=_scaled(sky, glow))
        zw = scene.wall_distance_m
        lm = scene.landmarks[int(rng.integers(len(scene.landmarks)))] if scene.landmarks else None
        x = (lm.x_m * zw / lm.z_m if lm else 0.0) + d.uniform(rng, -0.3, 0.3) * zw
        half = d.uniform(rng, 0.12, 0.3) * zw
        bottom = d.uniform(rng, 0.0, 0.08)
        window = Poster(x - half, x + half, bottom, bottom + d.uniform(rng, 0.4, 1.5), sky, glow)
        return dataclasses.replace(scene, posters=(*scene.posters, window))
    return scene
