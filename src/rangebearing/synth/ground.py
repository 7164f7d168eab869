"""Light on the floor around what stands on it: soft shadows and ambient occlusion.

A path tracer darkens the floor under and beside every robot: the robot hides
part of the sky (ambient occlusion, strongest at its base) and casts a shadow
from the main light whose edge is soft because the light has a size. With
``Scene.floor_shading`` the floor (and its mats) gets both:

- **Shadow**: the fraction of :data:`SAMPLES` directions spread over a disc of
  angular radius ``Lighting.light_radius_deg`` around the light that reach a
  floor point past each object standing on it (shadow rays against that
  object's own primitives, baked once per frame into an 8 mm grid on the floor
  around it and looked up bilinearly; the sample pattern turns from cell to
  cell, so a penumbra is a smooth ramp, not steps).
- **Ambient occlusion**: each object as a vertical cylinder (its footprint
  radius and height); a cylinder at distance ``d`` covering azimuth ``Δφ`` up to
  elevation ``e`` hides ``Δφ·sin²e / 2π`` of the cosine-weighted sky.

Only the floor receives these; landmarks keep the shadows of :mod:`.shadows`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Dict, List, Sequence, Tuple

import numpy as np

from . import shadows
from .shapes import Primitive

SAMPLES = 6
CELL_M = 0.008  # shadow grid on the floor
MAX_SHADOW_M = 0.6  # a low light's shadows are cut there
_GOLDEN = math.pi * (3.0 - math.sqrt(5.0))


@dataclass(frozen=True)
class Standing:
    """One object on the floor: the cylinder around it and its shadow, baked into a
    grid of :data:`CELL_M` cells on the floor (the fraction of the light that gets past)."""

    x: float
    z: float
    radius: float
    height: float
    origin: Tuple[float, float]  # (x, z) of the grid's first cell centre
    lit: np.ndarray  # (rows along z, cols along x)


@dataclass(frozen=True)
class Ground:
    """What shades the floor: the objects, and the floor's ambient and direct
    irradiance (RGB) without them."""

    objects: Tuple[Standing, ...]
    ambient: np.ndarray
    direct: np.ndarray


def standing(prims: Sequence[Primitive], groups: Sequence[Sequence[int]], light: np.ndarray,
             radius_deg: float) -> Tuple[Standing, ...]:
    """Objects from primitive index groups (a robot's parts and its landmark together),
    each with its shadow from a light of angular radius ``radius_deg`` towards ``light``."""
    dirs = light_samples(light, radius_deg)
    out = []
    for g in groups:
        ps = tuple(prims[i] for i in g)
        ext = np.array([p.extent() for p in ps])
        # parts thinner than a shadow-grid cell both ways (a camera bracket) cast nothing visible
        big = tuple(p for p, e in zip(ps, ext) if max(e[1] - e[0], e[5] - e[4]) > CELL_M)
        if ext[:, 2].min() > 0.02:  # not standing on the floor
            continue
        x0, x1, z0, z1 = ext[:, 0].min(), ext[:, 1].max(), ext[:, 4].min(), ext[:, 5].max()
        top = float(ext[:, 3].max())
        key = (tuple((type(p).__name__, p.extent()) for p in big), tuple(light), radius_deg)
        baked = _BAKED.pop(key, None) or _bake(big, (x0, x1, z0, z1), top, dirs, light, radius_deg)
        _BAKED[key] = baked  # the most recent last: a still robot of a sequence is baked once
        while len(_BAKED) > 64:
            del _BAKED[next(iter(_BAKED))]
        out.append(Standing((x0 + x1) / 2, (z0 + z1) / 2, 0.25 * ((x1 - x0) + (z1 - z0)), top, *baked))
    return tuple(out)


_BAKED: Dict[tuple, Tuple[Tuple[float, float], np.ndarray]] = {}


def _bake(prims: Tuple[Primitive, ...], box: Tuple[float, float, float, float], top: float,
          dirs: np.ndarray, light: np.ndarray, radius_deg: float
          ) -> Tuple[Tuple[float, float], np.ndarray]:
    """The object's shadow on a floor grid around it and its shadow's reach."""
    x0, x1, z0, z1 = box
    scale = min(top / max(light[1], 0.1), MAX_SHADOW_M)
    ox, oz = -light[0] * scale, -light[2] * scale
    margin = top * math.tan(math.radians(radius_deg)) / max(light[1], 0.1) + 2 * CELL_M
    gx0, gx1 = min(x0, x0 + ox) - margin, max(x1, x1 + ox) + margin
    gz0, gz1 = min(z0, z0 + oz) - margin, max(z1, z1 + oz) + margin
    xs = np.arange(gx0, gx1 + CELL_M, CELL_M)
    zs = np.arange(gz0, gz1 + CELL_M, CELL_M)
    zz, xx = np.meshgrid(zs, xs, indexing="ij")
    pts = np.stack([xx.ravel(), np.zeros(xx.size), zz.ravel()], axis=1)
    turned = _turn(dirs, pts, light) if len(dirs) > 1 else np.broadcast_to(dirs[None], (len(pts), 1, 3))
    seen = np.zeros(len(pts))
    for s in range(turned.shape[1]):
        seen += shadows.lit(pts, np.ascontiguousarray(turned[:, s]), None, prims)
    grid = (seen / turned.shape[1]).reshape(xx.shape).astype(np.float32)
    return (float(xs[0]), float(zs[0])), grid


def light_samples(light: np.ndarray, radius_deg: float) -> np.ndarray:
    """:data:`SAMPLES` unit directions on a disc (Vogel spiral) of ``radius_deg`` around ``light``."""
    if radius_deg <= 0:
        return np.repeat(light[None], 1, axis=0)
    helper = np.array([0.0, 0.0, 1.0]) if abs(light[1]) > 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(light, helper)
    u /= np.linalg.norm(u)
    v = np.cross(light, u)
    k = np.arange(SAMPLES)
    r = math.tan(math.radians(radius_deg)) * np.sqrt((k + 0.5) / SAMPLES)
    a = k * _GOLDEN
    d = light[None] + r[:, None] * (np.cos(a)[:, None] * u + np.sin(a)[:, None] * v)
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _turn(dirs: np.ndarray, pts: np.ndarray, light: np.ndarray) -> np.ndarray:
    """The sample pattern turned about the light by a per-point angle: (K, S, 3)."""
    phase = np.modf(np.abs(np.sin(pts[:, 0] * 127.1 + pts[:, 2] * 311.7)) * 43758.5453)[0] * 2 * math.pi
    c, s = np.cos(phase)[:, None, None], np.sin(phase)[:, None, None]
    along = (dirs @ light)[None, :, None] * light
    perp = dirs[None] - along
    cross = np.cross(light, dirs)[None]
    return along + c * perp + s * cross


def _occlusion(obj: Standing, pts: np.ndarray) -> np.ndarray:
    d = np.hypot(pts[:, 0] - obj.x, pts[:, 2] - obj.z)
    with np.errstate(divide="ignore", invalid="ignore"):
        dphi = 2.0 * np.arcsin(np.minimum(obj.radius / np.maximum(d, 1e-9), 1.0))
        gap = np.maximum(d - obj.radius, 1e-4)
        s2 = obj.height**2 / (obj.height**2 + gap**2)
    return np.where(d <= obj.radius, 0.9, dphi * s2 / (2.0 * math.pi))


def _lookup(obj: Standing, pts: np.ndarray) -> np.ndarray:
    """Bilinear look-up of the baked shadow (1 outside the grid)."""
    rows, cols = obj.lit.shape
    ok = ((pts[:, 0] >= obj.origin[0]) & (pts[:, 0] <= obj.origin[0] + (cols - 1) * CELL_M)
          & (pts[:, 2] >= obj.origin[1]) & (pts[:, 2] <= obj.origin[1] + (rows - 1) * CELL_M))
    out = np.ones(len(pts))
    if ok.any():
        uu = (pts[ok, 0] - obj.origin[0]) / CELL_M
        vv = (pts[ok, 2] - obj.origin[1]) / CELL_M
        c0 = np.minimum(uu.astype(int), cols - 2)
        r0 = np.minimum(vv.astype(int), rows - 2)
        fu, fv = uu - c0, vv - r0
        g = obj.lit
        out[ok] = ((1 - fv) * ((1 - fu) * g[r0, c0] + fu * g[r0, c0 + 1])
                   + fv * ((1 - fu) * g[r0 + 1, c0] + fu * g[r0 + 1, c0 + 1]))
    return out


def _reach(obj: Standing) -> Tuple[float, float, float, float]:
    """The floor rectangle (x0, x1, z0, z1) outside which ``obj`` changes nothing that matters."""
    r = obj.radius + 2.5 * obj.height  # AO there is below 0.1 %
    rows, cols = obj.lit.shape
    return (min(obj.x - r, obj.origin[0]), max(obj.x + r, obj.origin[0] + cols * CELL_M),
            min(obj.z - r, obj.origin[1]), max(obj.z + r, obj.origin[1] + rows * CELL_M))


def factor(ground: Ground, pts: np.ndarray) -> np.ndarray:
    """(K, 3) multipliers of the floor radiance at floor points ``pts`` (K, 3)."""
    out = np.ones((len(pts), 3))
    blocked = np.zeros(len(pts))
    lit = np.ones(len(pts))
    touched = np.zeros(len(pts), bool)
    for obj in ground.objects:
        x0, x1, z0, z1 = _reach(obj)
        idx = np.flatnonzero((pts[:, 0] > x0) & (pts[:, 0] < x1) & (pts[:, 2] > z0) & (pts[:, 2] < z1))
        if idx.size:
            blocked[idx] += _occlusion(obj, pts[idx])
            lit[idx] *= _lookup(obj, pts[idx])
            touched[idx] = True
    ao = 1.0 - np.minimum(blocked[touched], 0.95)
    total = ground.ambient + ground.direct
    out[touched] = ((ao[:, None] * ground.ambient + lit[touched, None] * ground.direct)
                    / np.maximum(total, 1e-9))
    return out


def groups(n_prims: int, landmarks: Sequence[int]) -> List[List[int]]:
    """Primitive index groups: each landmark with the robot parts built before it, then
    every other primitive on its own."""
    out, start = [], 0
    for k in landmarks:
        out.append(list(range(start, k + 1)))
        start = k + 1
    out.extend([i] for i in range(start, n_prims))
    return out
