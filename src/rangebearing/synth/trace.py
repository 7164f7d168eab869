"""Ray casting against the floor, the back wall, vertical cylinders and boxes.

Rays start at the camera centre ``(0, h, 0)`` with direction ``(dx, dy, 1)``
(world frame, Y up), so the ray parameter ``t`` of a hit IS its depth Z and
one buffer of ``t`` serves as the depth test. Every surface writes the linear
radiance it reflects, ``albedo · (ambient + (1 − ambient)·max(0, n·l))``, and an
integer id that changes wherever colour or normal jumps (the renderer
supersamples pixels next to an id change).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import List, Tuple, Union

import numpy as np

from .scene import BLUE_PAINT, CAP_GREY, RED_PAINT, ROBOT_BODY, ROBOT_TOP, WHITE_PAINT, Scene

ID_BACKGROUND, ID_WALL, ID_FLOOR = 0, 1, 2
ID_PATCH, ID_POSTER, ID_OBJECT = 16, 256, 1024
PARTS = 16  # ids per object


@dataclass
class Hits:
    """Nearest hit found so far, per ray: depth, id and linear RGB radiance."""

    t: np.ndarray
    ident: np.ndarray
    rad: np.ndarray

    def view(self, index: Union[Tuple[slice, ...], np.ndarray]) -> Hits:
        return Hits(self.t[index], self.ident[index], self.rad[index])

    def put(self, index: Union[Tuple[slice, ...], np.ndarray], part: Hits) -> None:
        self.t[index], self.ident[index], self.rad[index] = part.t, part.ident, part.rad


@dataclass(frozen=True)
class Shader:
    """Lambertian shading with a unit direction towards the light and an ambient floor."""

    light: np.ndarray
    ambient: float

    @classmethod
    def from_scene(cls, scene: Scene) -> Shader:
        d = np.asarray(scene.lighting.direction, dtype=np.float64)
        return cls(d / np.linalg.norm(d), float(scene.lighting.ambient))

    def __call__(self, albedo: np.ndarray, cos: np.ndarray) -> np.ndarray:
        k = self.ambient + (1.0 - self.ambient) * np.maximum(cos, 0.0)
        return np.asarray(albedo) * k[..., None]


@dataclass(frozen=True)
class Cyl:
    """A vertical cylinder made of coloured segments; ``bounds[i]`` is segment i's bottom."""

    x: float
    z: float
    r: float
    y0: float
    y1: float
    bounds: np.ndarray
    colours: np.ndarray  # (segments, 3)
    cap: np.ndarray  # colour of the flat ends
    ident: int

    def extent(self) -> Tuple[float, float, float, float, float, float]:
        return self.x - self.r, self.x + self.r, self.y0, self.y1, self.z - self.r, self.z + self.r


@dataclass(frozen=True)
class Cuboid:
    """An axis-aligned box."""

    x0: float
    x1: float
    y0: float
    y1: float
    z0: float
    z1: float
    colour: np.ndarray
    ident: int

    def extent(self) -> Tuple[float, float, float, float, float, float]:
        return self.x0, self.x1, self.y0, self.y1, self.z0, self.z1


Primitive = Union[Cyl, Cuboid]


def primitives(scene: Scene) -> List[Primitive]:
    """The scene's objects as primitives, each with its own block of ids."""
    out: List[Primitive] = []
    g = scene.geometry

    def ident() -> int:
        return ID_OBJECT + PARTS * len(out)

    for lm in scene.landmarks:
        b = lm.base_height_m
        out.append(Cyl(lm.x_m, lm.z_m, scene.robot_radius_m, 0.0, b, np.array([0.0]),
                       np.array([ROBOT_BODY]), np.array(ROBOT_TOP), ident()))
        bounds = np.array([b, b + g.band_height_m, b + g.height_m - g.band_height_m])
        colours = np.array([BLUE_PAINT, WHITE_PAINT, RED_PAINT])
        out.append(Cyl(lm.x_m, lm.z_m, g.radius_m, b, b + g.height_m, bounds, colours,
                       np.array(CAP_GREY), ident()))
    for c in scene.cylinders:
        out.append(Cyl(c.x_m, c.z_m, c.radius_m, c.bottom_m, c.top_m, np.array([c.bottom_m]),
                       np.array([c.colour]), np.array(c.colour), ident()))
    for bx in scene.boxes:
        out.append(Cuboid(bx.x_m - bx.width_m / 2, bx.x_m + bx.width_m / 2, bx.bottom_m, bx.top_m,
                          bx.z_m - bx.depth_m / 2, bx.z_m + bx.depth_m / 2, np.array(bx.colour),
                          ident()))
    return out


def trace_background(dx: np.ndarray, dy: np.ndarray, scene: Scene, shade: Shader) -> Hits:
    """Fresh hit buffers holding the floor (Y = 0, with patches), the back wall
    (Z = const, with posters) and, where neither is hit, the background colour.

    Dense (no masked gathers): floor and wall radiance are constant per colour,
    so every surface is one palette entry.
    """
    h, zw = scene.camera_height_m, scene.wall_distance_m
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(dy < 0, h / -dy, np.inf)
    palette = np.zeros((ID_POSTER + len(scene.posters), 3))
    palette[ID_BACKGROUND] = scene.background_colour
    palette[ID_FLOOR] = shade(np.asarray(scene.floor_colour), np.asarray(shade.light[1]))
    ident = np.where(np.isfinite(t), ID_FLOOR, ID_BACKGROUND).astype(np.int32)
    if scene.floor_patches:
        x = dx * t
        for i, p in enumerate(scene.floor_patches):
            palette[ID_PATCH + i] = shade(np.asarray(p.colour), np.asarray(shade.light[1]))
            m = (x >= p.x_min_m) & (x <= p.x_max_m) & (t >= p.z_min_m) & (t <= p.z_max_m)
            ident[m] = ID_PATCH + i
    if zw is not None:
        wall = zw < t
        t = np.where(wall, zw, t)
        ident[wall] = ID_WALL
        palette[ID_WALL] = shade(np.asarray(scene.wall_colour), np.asarray(-shade.light[2]))
        if scene.posters:
            x, y = dx * zw, h + dy * zw
            for i, p in enumerate(scene.posters):
                palette[ID_POSTER + i] = shade(np.asarray(p.colour), np.asarray(-shade.light[2]))
                m = wall & (x >= p.x_min_m) & (x <= p.x_max_m) & (y >= p.bottom_m) & (y <= p.top_m)
                ident[m] = ID_POSTER + i
    return Hits(t, ident, np.take(palette, ident, axis=0))


def trace_cylinder(dx: np.ndarray, dy: np.ndarray, h: float, c: Cyl, shade: Shader,
                   hits: Hits) -> None:
    """Side (nearest root of the circle equation in the XZ plane) and the visible end cap."""
    cc = c.x * c.x + c.z * c.z - c.r * c.r
    if cc <= 0.0:  # the camera is inside the cylinder's footprint
        return
    a = dx * dx + 1.0
    b = dx * c.x + c.z
    disc = b * b - a * cc
    with np.errstate(invalid="ignore"):
        t = (b - np.sqrt(disc)) / a
    y = h + t * dy
    side = (disc >= 0.0) & (t > 0.0) & (y >= c.y0) & (y <= c.y1) & (t < hits.t)
    if side.any():
        ts, ys = t[side], y[side]
        nx, nz = (dx[side] * ts - c.x) / c.r, (ts - c.z) / c.r
        seg = np.clip(np.searchsorted(c.bounds, ys, side="right") - 1, 0, len(c.bounds) - 1)
        hits.t[side], hits.ident[side] = ts, c.ident + seg
        hits.rad[side] = shade(c.colours[seg], nx * shade.light[0] + nz * shade.light[2])
    if h > c.y1:
        yc, sign, part = c.y1, 1.0, PARTS - 1
    elif h < c.y0:
        yc, sign, part = c.y0, -1.0, PARTS - 2
    else:
        return
    with np.errstate(divide="ignore", invalid="ignore"):
        tc = (yc - h) / dy
    xc = dx * tc
    cap = (tc > 0.0) & ((xc - c.x) ** 2 + (tc - c.z) ** 2 <= c.r * c.r) & (tc < hits.t)
    if cap.any():
        hits.t[cap], hits.ident[cap] = tc[cap], c.ident + part
        hits.rad[cap] = shade(c.cap, np.full(int(cap.sum()), sign * shade.light[1]))


def trace_box(dx: np.ndarray, dy: np.ndarray, h: float, b: Cuboid, shade: Shader,
              hits: Hits) -> None:
    """Slab test; the face entered gives the normal."""
    sx = np.where(dx == 0.0, 1e-300, dx)
    sy = np.where(dy == 0.0, 1e-300, dy)
    tx0, tx1 = b.x0 / sx, b.x1 / sx
    ty0, ty1 = (b.y0 - h) / sy, (b.y1 - h) / sy
    txn, tyn = np.minimum(tx0, tx1), np.minimum(ty0, ty1)
    tnear = np.maximum(np.maximum(txn, tyn), b.z0)
    tfar = np.minimum(np.minimum(np.maximum(tx0, tx1), np.maximum(ty0, ty1)), b.z1)
    hit = (tnear <= tfar) & (tnear > 0.0) & (tnear < hits.t)
    if not hit.any():
        return
    tn, xn, yn = tnear[hit], txn[hit], tyn[hit]
    face = np.where(tn == xn, np.where(dx[hit] > 0, 0, 1), np.where(tn == yn,
                    np.where(dy[hit] > 0, 2, 3), 4))
    normals = np.array([[-1, 0, 0], [1, 0, 0], [0, -1, 0], [0, 1, 0], [0, 0, -1]], float)
    hits.t[hit], hits.ident[hit] = tn, b.ident + face
    hits.rad[hit] = shade(b.colour, normals[face] @ shade.light)


def trace(dx: np.ndarray, dy: np.ndarray, h: float, prim: Primitive, shade: Shader,
          hits: Hits) -> None:
    """Intersect one primitive and keep the nearer hits."""
    if isinstance(prim, Cyl):
        trace_cylinder(dx, dy, h, prim, shade, hits)
    else:
        trace_box(dx, dy, h, prim, shade, hits)
