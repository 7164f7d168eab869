"""Shading: Lambert under a directional light and ambient, plus spots and highlights.

:class:`Shader` keeps the original scalar form, ``albedo · (ambient + (1 −
ambient)·max(0, n·l))``, for plain light (white, no spots, no gloss), so the
original presets render bit for bit as before; :meth:`Shader.rich` handles
coloured light, point lights with a cone, Blinn-Phong highlights, shadows
cast onto landmarks (:mod:`.shadows`) and ambient light tinted by the room's
floor and wall (:func:`bounce`), and needs each hit's normal and position.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, Optional, Sequence, Tuple

import numpy as np

from . import bounce as local
from . import ground, shadows
from .scene import Scene
from .shapes import Primitive

NEUTRAL_FLOOR, NEUTRAL_WALL = 0.60, 0.78  # the default room: no tint


def bounce(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Tints of the ambient light arriving from above and from below, from the room's
    colours (one bounce, roughly): 1 for a neutral grey room; a red wall makes the light
    from above reddish, a navy carpet the light from below dark blue."""
    wall = np.asarray(scene.wall_colour if scene.wall_distance_m is not None else (NEUTRAL_WALL,) * 3)
    up = 0.5 + 0.5 * np.minimum(wall / NEUTRAL_WALL, 1.3)  # half from a white ceiling
    down = np.minimum(np.asarray(scene.floor_colour) / NEUTRAL_FLOOR, 1.3)
    return up, 0.3 + 0.7 * down  # part of it comes off the walls and robots


@dataclass(frozen=True)
class Shader:
    """Light of one scene, ready to shade hits (unit direction towards the light)."""

    light: np.ndarray
    ambient: float
    plain: bool = True
    colour: np.ndarray = field(default_factory=lambda: np.ones(3))
    ambient_colour: np.ndarray = field(default_factory=lambda: np.ones(3))
    spot_pos: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    spot_axis: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    spot_power: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # intensity · colour
    spot_cone: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # cos of the inner and outer half-angles
    gloss: float = 0.0
    shininess: float = 60.0
    eye: Tuple[float, float, float] = (0.0, 0.1, 0.0)
    casters: shadows.Casters = field(default_factory=shadows.empty_casters)
    bounce_up: np.ndarray = field(default_factory=lambda: np.ones(3))
    bounce_down: np.ndarray = field(default_factory=lambda: np.ones(3))
    ground: Optional[ground.Ground] = None
    nearby: Dict[int, local.Nearby] = field(default_factory=dict)
    fresnel: float = 0.0

    @classmethod
    def from_scene(cls, scene: Scene, prims: Optional[Sequence[Primitive]] = None,
                   landmarks: Sequence[int] = ()) -> Shader:
        """The scene's light; with its primitives (and which are landmarks), under rich
        light the landmarks also receive shadows from the others."""
        li = scene.lighting
        d = np.asarray(li.direction, dtype=np.float64)
        light = d / np.linalg.norm(d)
        if li.plain:
            return cls(light, float(li.ambient))
        pos = np.array([s.position for s in li.spots], dtype=np.float64).reshape(-1, 3)
        axis = np.array([s.target for s in li.spots], dtype=np.float64).reshape(-1, 3) - pos
        axis /= np.maximum(np.linalg.norm(axis, axis=1, keepdims=True), 1e-12)
        power = np.array([np.multiply(s.colour, s.intensity) for s in li.spots]).reshape(-1, 3)
        cone = np.array([(np.cos(np.radians(s.cone_deg)), np.cos(np.radians(s.cone_deg + s.soft_deg)))
                         for s in li.spots]).reshape(-1, 2)
        cast = shadows.casters(prims, landmarks, light, pos) if prims is not None else {}
        up, down = bounce(scene)
        floor = None
        if scene.floor_shading and prims is not None:
            objects = ground.standing(prims, ground.groups(len(prims), landmarks), light,
                                      li.light_radius_deg)
            floor = ground.Ground(objects, li.ambient * np.asarray(li.ambient_colour, float) * up,
                                  (1.0 - li.ambient) * max(light[1], 0.0) * np.asarray(li.colour, float))
        near = local.nearby(prims, landmarks, down) if scene.local_bounce and prims is not None else {}
        return cls(light, float(li.ambient), False, np.asarray(li.colour, float),
                   np.asarray(li.ambient_colour, float), pos, axis, power, cone,
                   float(li.gloss), float(li.shininess), (0.0, scene.camera_height_m, 0.0), cast,
                   up, down, floor, near, float(li.fresnel))

    def __call__(self, albedo: np.ndarray, cos: np.ndarray) -> np.ndarray:
        """Plain Lambert: ``cos`` is n·l per hit; returns (..., 3) radiance."""
        k = self.ambient + (1.0 - self.ambient) * np.maximum(cos, 0.0)
        return np.asarray(albedo) * k[..., None]

    def rich(self, albedo: np.ndarray, normal: np.ndarray, point: np.ndarray,
             glossy: bool = False, owner: Optional[int] = None) -> np.ndarray:
        """Radiance (K, 3) of hits with unit ``normal`` and ``point`` (K, 3), world frame;
        ``owner`` (a landmark's id) makes the hits receive shadows."""
        albedo = np.broadcast_to(np.asarray(albedo, dtype=np.float64), point.shape)
        normal = np.broadcast_to(normal, point.shape)
        cos = normal @ self.light
        sun, per_spot = self.casters.get(owner, ((), ())) if owner is not None else ((), ())
        direct = (1.0 - self.ambient) * np.maximum(cos, 0.0)
        if sun:
            direct = direct * shadows.lit(point, self.light, None, sun)
        w_up = 0.5 * (1.0 + normal[:, 1:2])
        room = w_up * self.bounce_up + (1.0 - w_up) * self.bounce_down
        if owner is not None and owner in self.nearby:
            room = room + local.room_change(self.nearby[owner], normal, point, self.bounce_down, room)
        irr = self.ambient * self.ambient_colour * room + direct[:, None] * self.colour
        spec = np.zeros(point.shape) if glossy and self.gloss > 0 else None
        view = None
        if spec is not None:
            view = np.asarray(self.eye) - point
            view /= np.maximum(np.linalg.norm(view, axis=1, keepdims=True), 1e-12)
            half = view + self.light
            half /= np.maximum(np.linalg.norm(half, axis=1, keepdims=True), 1e-12)
            nh = np.clip(np.einsum("ij,ij->i", normal, half), 0.0, None)
            spec += (direct > 0)[:, None] * (1.0 - self.ambient) * nh[:, None] ** self.shininess * self.colour
        for i, (pos, axis, power, (inner, outer)) in enumerate(
                zip(self.spot_pos, self.spot_axis, self.spot_power, self.spot_cone)):
            to = pos - point
            d2 = np.maximum(np.einsum("ij,ij->i", to, to), 1e-6)
            ldir = to / np.sqrt(d2)[:, None]
            off = -ldir @ axis  # cos of the angle off the spot's axis
            fall = np.clip((off - outer) / max(inner - outer, 1e-9), 0.0, 1.0)
            fall = fall * fall * (3.0 - 2.0 * fall)
            lam = np.maximum(np.einsum("ij,ij->i", normal, ldir), 0.0)
            if per_spot and per_spot[i]:
                lam = lam * shadows.lit(point, ldir, np.sqrt(d2), per_spot[i])
            e = fall / d2
            irr += (lam * e)[:, None] * power
            if spec is not None and view is not None:
                half = view + ldir
                half /= np.maximum(np.linalg.norm(half, axis=1, keepdims=True), 1e-12)
                nh = np.clip(np.einsum("ij,ij->i", normal, half), 0.0, None)
                spec += ((lam > 0) * e * nh**self.shininess)[:, None] * power
        out = albedo * irr
        if spec is not None:
            out += self.gloss * spec
        if glossy and self.fresnel > 0:
            out = self._mirror(out, normal, point)
        return out

    def _mirror(self, diffuse: np.ndarray, normal: np.ndarray, point: np.ndarray) -> np.ndarray:
        """Glossy plastic: the room's radiance in the mirror direction, by Fresnel's share."""
        view = np.asarray(self.eye) - point
        view /= np.maximum(np.linalg.norm(view, axis=1, keepdims=True), 1e-12)
        r = local.fresnel(normal, view)[:, None] * self.fresnel
        refl_y = 2.0 * np.einsum("ij,ij->i", normal, view)[:, None] * normal[:, 1:2] - view[:, 1:2]
        w = 0.5 * (1.0 + refl_y)
        level = self.ambient * self.ambient_colour + 0.5 * (1.0 - self.ambient) * self.colour
        room = local.ROOM_ALBEDO * level * (w * self.bounce_up + (1.0 - w) * self.bounce_down)
        return (1.0 - r) * diffuse + r * room
