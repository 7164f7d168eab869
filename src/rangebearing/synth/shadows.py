"""Shadows cast onto landmarks: which lights a point on a landmark's paint can see.

Only the landmarks' surfaces receive shadows (they are what a detector
measures); floors, walls and robots are lit unshadowed. For each landmark and
each light, the candidate casters are the primitives whose bounding sphere
comes near the path from the landmark to that light; a shadow ray from each
hit point is then tested against those alone.
"""

from __future__ import annotations

import math
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from .shapes import Cuboid, Cyl, OBox, Primitive

EPS_M = 1e-6
Casters = Dict[int, Tuple[Tuple[Primitive, ...], Tuple[Tuple[Primitive, ...], ...]]]


def _sphere(p: Primitive) -> Tuple[np.ndarray, float]:
    x0, x1, y0, y1, z0, z1 = p.extent()
    c = np.array([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2])
    return c, 0.5 * math.sqrt((x1 - x0) ** 2 + (y1 - y0) ** 2 + (z1 - z0) ** 2)


def _near(centre: np.ndarray, radius: float, to: np.ndarray, length: float, p: Primitive,
          floor_m: float) -> bool:
    """Whether ``p`` comes near the path from a landmark to a light (and, for a light
    above, reaches higher than the landmark's bottom ``floor_m``)."""
    if to[1] > 0 and p.extent()[3] <= floor_m + 1e-9:
        return False
    c, r = _sphere(p)
    rel = c - centre
    t = float(np.clip(rel @ to, 0.0, length))
    return float(np.linalg.norm(rel - t * to)) <= r + radius


def casters(prims: Sequence[Primitive], landmarks: Sequence[int], light: np.ndarray,
            spots: np.ndarray) -> Casters:
    """For every landmark primitive (by index), the primitives that may shadow it from
    the directional light and from each spot (``spots``: (S, 3) positions)."""
    out: Casters = {}
    for k in landmarks:
        own = prims[k]
        centre, radius = _sphere(own)
        others = [p for j, p in enumerate(prims) if j != k]
        bottom = own.extent()[2]
        sun = tuple(p for p in others if _near(centre, radius, light, 1e3, p, bottom))
        per_spot = []
        for s in spots:
            to = s - centre
            dist = float(np.linalg.norm(to))
            unit = to / max(dist, 1e-9)
            per_spot.append(tuple(p for p in others if _near(centre, radius, unit, dist, p, bottom)))
        out[own.ident] = (sun, tuple(per_spot))
    return out


def _hits_cyl(c: Cyl, o: np.ndarray, d: np.ndarray, tmax: np.ndarray) -> np.ndarray:
    ox, oz = o[:, 0] - c.x, o[:, 2] - c.z
    dx, dy, dz = d[:, 0], d[:, 1], d[:, 2]
    a = dx * dx + dz * dz
    b = ox * dx + oz * dz
    cc = ox * ox + oz * oz - c.r * c.r
    disc = b * b - a * cc
    blocked = np.zeros(len(o), dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.sqrt(np.maximum(disc, 0.0))
        for t in ((-b - root) / a, (-b + root) / a):
            y = o[:, 1] + t * dy
            blocked |= (disc >= 0) & (a > 0) & (t > EPS_M) & (t < tmax) & (y >= c.y0) & (y <= c.y1)
        for yc in (c.y0, c.y1):
            t = (yc - o[:, 1]) / dy
            inside = (ox + t * dx) ** 2 + (oz + t * dz) ** 2 <= c.r * c.r
            blocked |= (t > EPS_M) & (t < tmax) & inside
    return blocked


def _slab(lo: np.ndarray, hi: np.ndarray, o: np.ndarray, d: np.ndarray, tmax: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / np.where(d == 0.0, 1e-300, d)
        t0, t1 = (lo - o) * inv, (hi - o) * inv
    tnear = np.minimum(t0, t1).max(axis=1)
    tfar = np.maximum(t0, t1).min(axis=1)
    return (tnear <= tfar) & (tfar > EPS_M) & (tnear < tmax)


def _hits_box(b: Primitive, o: np.ndarray, d: np.ndarray, tmax: np.ndarray) -> np.ndarray:
    if isinstance(b, Cuboid):
        return _slab(np.array([b.x0, b.y0, b.z0]), np.array([b.x1, b.y1, b.z1]), o, d, tmax)
    assert isinstance(b, OBox)
    fwd, across = b.axes
    rel = o - np.array([b.x, 0.0, b.z])
    lo_ = np.stack([rel @ fwd, rel[:, 1], rel @ across], axis=1)
    dl = np.stack([d @ fwd, d[:, 1], d @ across], axis=1)
    return _slab(np.array([-b.half_long, b.y0, -b.half_across]),
                 np.array([b.half_long, b.y1, b.half_across]), lo_, dl, tmax)


def lit(points: np.ndarray, to_light: np.ndarray, dist: Optional[np.ndarray],
        blockers: Sequence[Primitive]) -> np.ndarray:
    """1.0 where the light (unit direction ``to_light``, (K, 3) or (3,), at ``dist`` or
    infinitely far) reaches ``points`` (K, 3) past every blocker, else 0.0."""
    k = len(points)
    if not blockers or k == 0:
        return np.ones(k)
    d = np.broadcast_to(to_light, points.shape)
    tmax = np.full(k, np.inf) if dist is None else np.asarray(dist)
    blocked = np.zeros(k, dtype=bool)
    for p in blockers:
        todo = ~blocked
        if not todo.any():
            break
        hit = (_hits_cyl(p, points[todo], d[todo], tmax[todo]) if isinstance(p, Cyl)
               else _hits_box(p, points[todo], d[todo], tmax[todo]))
        blocked[np.flatnonzero(todo)[hit]] = True
    return (~blocked).astype(np.float64)


def empty_casters() -> Casters:
    return {}


__all__: List[str] = ["casters", "empty_casters", "lit"]
