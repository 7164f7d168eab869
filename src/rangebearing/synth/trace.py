"""Ray casting against the floor, the back wall, vertical cylinders and boxes.

Rays start at the camera centre ``(0, h, 0)`` with direction ``(dx, dy, 1)``
(world frame, Y up), so the ray parameter ``t`` of a hit IS its depth Z and
one buffer of ``t`` serves as the depth test. Every surface writes the linear
radiance it reflects (see :mod:`.lights`) and an integer id that changes
wherever colour or normal jumps (the renderer supersamples pixels next to an
id change).
"""

from __future__ import annotations

import numpy as np

from . import ground, surfaces, texture
from .lights import Shader
from .parts import build, primitives
from .scene import Scene
from .shapes import (
    ID_BACKGROUND,
    ID_FLOOR,
    ID_OBJECT,
    ID_PATCH,
    ID_POSTER,
    ID_WALL,
    PARTS,
    Cuboid,
    Cyl,
    Hits,
    OBox,
    Primitive,
)

__all__ = ["ID_BACKGROUND", "ID_FLOOR", "ID_OBJECT", "ID_PATCH", "ID_POSTER", "ID_WALL", "PARTS",
           "Cuboid", "Cyl", "Hits", "OBox", "Primitive", "Shader", "build", "primitives", "trace",
           "trace_background"]

_BOX_NORMALS = np.array([[-1, 0, 0], [1, 0, 0], [0, -1, 0], [0, 1, 0], [0, 0, -1]], float)


def _points(dx: np.ndarray, dy: np.ndarray, h: float, t: np.ndarray) -> np.ndarray:
    return np.stack([dx * t, h + dy * t, t], axis=-1)


def trace_background(dx: np.ndarray, dy: np.ndarray, scene: Scene, shade: Shader) -> Hits:
    """Fresh hit buffers holding the floor (Y = 0, with patches), the back wall
    (Z = const, with posters) and, where neither is hit, the background colour.

    Dense (no masked gathers): under plain light floor and wall radiance are
    constant per colour, so every surface is one palette entry; under rich
    light the palette holds albedos, shaded per pixel.
    """
    h, zw = scene.camera_height_m, scene.wall_distance_m
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(dy < 0, h / -dy, np.inf)
    rich = not shade.plain and len(shade.spot_pos) > 0  # shaded per pixel
    normals = {"floor": np.array([0.0, 1.0, 0.0]), "wall": np.array([0.0, 0.0, -1.0])}

    def lit(colour: object, surface: str) -> np.ndarray:
        """A surface's radiance (its albedo when shaded per pixel later)."""
        if rich:
            return np.asarray(colour, float)
        if shade.plain:
            return shade(np.asarray(colour), np.asarray(normals[surface] @ shade.light))
        return shade.rich(np.asarray(colour, float)[None], normals[surface][None], np.zeros((1, 3)))[0]

    palette = np.zeros((ID_POSTER + len(scene.posters), 3))
    palette[ID_BACKGROUND] = scene.background_colour
    palette[ID_FLOOR] = lit(scene.floor_colour, "floor")
    ident = np.where(np.isfinite(t), ID_FLOOR, ID_BACKGROUND).astype(np.int32)
    if scene.floor_patches:
        x = dx * t
        for i, p in enumerate(scene.floor_patches):
            palette[ID_PATCH + i] = lit(p.colour, "floor")
            m = (x >= p.x_min_m) & (x <= p.x_max_m) & (t >= p.z_min_m) & (t <= p.z_max_m)
            ident[m] = ID_PATCH + i
    glow = []
    if zw is not None:
        wall = zw < t
        t = np.where(wall, zw, t)
        ident[wall] = ID_WALL
        palette[ID_WALL] = lit(scene.wall_colour, "wall")
        if scene.posters:
            x, y = dx * zw, h + dy * zw
            for i, p in enumerate(scene.posters):
                if p.emission > 0:
                    glow.append(ID_POSTER + i)
                    palette[ID_POSTER + i] = np.multiply(p.colour, p.emission)
                else:
                    palette[ID_POSTER + i] = lit(p.colour, "wall")
                m = wall & (x >= p.x_min_m) & (x <= p.x_max_m) & (y >= p.bottom_m) & (y <= p.top_m)
                ident[m] = ID_POSTER + i
    rad = np.take(palette, ident, axis=0)
    if rich:
        surf = (ident != ID_BACKGROUND) & ~np.isin(ident, glow)
        flat = surf.ravel()
        if flat.any():
            normal = np.where((ident == ID_FLOOR) | ((ident >= ID_PATCH) & (ident < ID_POSTER)),
                              1, 0).ravel()[flat]
            normals = np.where(normal[:, None] == 1, [[0.0, 1.0, 0.0]], [[0.0, 0.0, -1.0]])
            pts = _points(dx, dy, h, t).reshape(-1, 3)[flat]
            shaded = shade.rich(rad.reshape(-1, 3)[flat], normals, pts)
            rad.reshape(-1, 3)[flat] = shaded
    if scene.floor_texture > 0 or scene.wall_texture > 0:
        _texture(rad, ident, dx, dy, t, scene)
    if scene.floor_pattern:
        floor = ident == ID_FLOOR
        if floor.any():
            tf = t[floor]
            cam = scene.camera
            rad[floor] *= surfaces.floor_gain(dx[floor] * tf, tf, tf / cam.fx_px, tf * tf / (h * cam.fy_px),
                                              scene.floor_pattern, scene.floor_pattern_params,
                                              scene.texture_seed + 2)
    if scene.brick_wall and zw is not None:
        wall = ident == ID_WALL
        if wall.any():
            rad[wall] *= surfaces.brick_gain(dx[wall] * zw, h + dy[wall] * zw,
                                             np.full(int(wall.sum()), zw / scene.camera.fx_px),
                                             scene.wall_colour, scene.texture_seed + 3)
    if shade.ground is not None and shade.ground.objects:
        floor = (ident == ID_FLOOR) | ((ident >= ID_PATCH) & (ident < ID_POSTER))
        if floor.any():
            rad[floor] *= ground.factor(shade.ground, _points(dx, dy, h, t)[floor])
    return Hits(t, ident, rad)


def _texture(rad: np.ndarray, ident: np.ndarray, dx: np.ndarray, dy: np.ndarray, t: np.ndarray,
             scene: Scene) -> None:
    """Multiply floor, mat and wall radiance by their albedo pattern, in place."""
    gain = np.ones(ident.shape)
    with np.errstate(invalid="ignore"):
        if scene.floor_texture > 0:
            floor = (ident == ID_FLOOR) | ((ident >= ID_PATCH) & (ident < ID_POSTER))
            tf = np.where(floor, t, 0.0)
            f = texture.factor(dx * tf, tf, scene.texture_seed, scene.floor_texture)
            gain = np.where(floor, f, gain)
        if scene.wall_texture > 0:
            wall = ident == ID_WALL
            tw = np.where(wall, t, 0.0)
            f = texture.factor(dx * tw, scene.camera_height_m + dy * tw, scene.texture_seed + 1,
                               scene.wall_texture)
            gain = np.where(wall, f, gain)
    rad *= gain[..., None]


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
        if shade.plain:
            hits.rad[side] = shade(c.colours[seg], nx * shade.light[0] + nz * shade.light[2])
        else:
            n = np.stack([nx, np.zeros_like(nx), nz], axis=-1)
            pts = np.stack([dx[side] * ts, ys, ts], axis=-1)
            hits.rad[side] = shade.rich(c.colours[seg], n, pts, c.glossy,
                                        c.ident if c.glossy else None)
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
        if shade.plain:
            hits.rad[cap] = shade(c.cap, np.full(int(cap.sum()), sign * shade.light[1]))
        else:
            pts = np.stack([xc[cap], np.full(int(cap.sum()), yc), tc[cap]], axis=-1)
            hits.rad[cap] = shade.rich(c.cap, np.array([0.0, sign, 0.0]), pts)


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
    hits.t[hit], hits.ident[hit] = tn, b.ident + face
    if shade.plain:
        hits.rad[hit] = shade(b.colour, _BOX_NORMALS[face] @ shade.light)
    else:
        hits.rad[hit] = shade.rich(b.colour, _BOX_NORMALS[face], _points(dx[hit], dy[hit], h, tn))


def trace_obox(dx: np.ndarray, dy: np.ndarray, h: float, b: OBox, shade: Shader,
               hits: Hits) -> None:
    """Slab test in the box's own frame (turned about the vertical through its centre)."""
    fwd, across = b.axes
    # ray o + t·d with o = (0, h, 0) − centre, d = (dx, dy, 1), projected on each axis
    oa, ob = -(b.x * fwd[0] + b.z * fwd[2]), -(b.x * across[0] + b.z * across[2])
    da, db = dx * fwd[0] + fwd[2], dx * across[0] + across[2]
    sa = np.where(da == 0.0, 1e-300, da)
    sb = np.where(db == 0.0, 1e-300, db)
    sy = np.where(dy == 0.0, 1e-300, dy)
    ta0, ta1 = (-b.half_long - oa) / sa, (b.half_long - oa) / sa
    tb0, tb1 = (-b.half_across - ob) / sb, (b.half_across - ob) / sb
    ty0, ty1 = (b.y0 - h) / sy, (b.y1 - h) / sy
    tan, tbn, tyn = np.minimum(ta0, ta1), np.minimum(tb0, tb1), np.minimum(ty0, ty1)
    tnear = np.maximum(np.maximum(tan, tbn), tyn)
    tfar = np.minimum(np.minimum(np.maximum(ta0, ta1), np.maximum(tb0, tb1)), np.maximum(ty0, ty1))
    hit = (tnear <= tfar) & (tnear > 0.0) & (tnear < hits.t)
    if not hit.any():
        return
    tn = tnear[hit]
    face = np.where(tn == tan[hit], np.where(da[hit] > 0, 0, 1),
                    np.where(tn == tbn[hit], np.where(db[hit] > 0, 2, 3),
                             np.where(dy[hit] > 0, 4, 5)))
    normals = np.stack([-fwd, fwd, -across, across, [0.0, -1.0, 0.0], [0.0, 1.0, 0.0]])
    hits.t[hit], hits.ident[hit] = tn, b.ident + face
    if shade.plain:
        hits.rad[hit] = shade(b.colour, normals[face] @ shade.light)
    else:
        hits.rad[hit] = shade.rich(b.colour, normals[face], _points(dx[hit], dy[hit], h, tn))


def trace(dx: np.ndarray, dy: np.ndarray, h: float, prim: Primitive, shade: Shader,
          hits: Hits) -> None:
    """Intersect one primitive and keep the nearer hits."""
    if isinstance(prim, Cyl):
        trace_cylinder(dx, dy, h, prim, shade, hits)
    elif isinstance(prim, OBox):
        trace_obox(dx, dy, h, prim, shade, hits)
    else:
        trace_box(dx, dy, h, prim, shade, hits)
