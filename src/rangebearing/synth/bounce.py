"""Light bounced onto a landmark by what is right next to it: colour bleeding, occlusion.

The room's one-bounce tint (:func:`.lights.bounce`) treats the surroundings as
far away. What stands within a few centimetres of a landmark fills a large part
of its view and replaces the room there, as a path tracer's second bounce would:

- **the robot's top board** right under the landmark (a green, blue, black or
  red PCB): from a point on the landmark's side at height ``Δ`` above it, a
  board reaching ``b`` beyond the surface fills ``½(1 − Δ/√(Δ² + b²))`` of the
  view (a strip below a vertical surface) in place of the floor, so the blue
  band is darker and tinted by the board, the red band hardly at all;
- **other objects nearby** (a neighbour's bands, its chassis, a red box, the
  robot's own camera board): each as a sphere of radius ``r`` (its area) at
  distance ``d`` fills ``(r/d)²·cos θ`` of the view, bringing its own colour
  (albedo relative to the room's) instead of the room's.

Landmark paint can also be glossy plastic: :func:`fresnel` gives the share of
the surroundings a dielectric (``F₀`` = 0.04) reflects at each viewing angle,
large at the silhouette, where the cylinder turns away from the camera.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Dict, Sequence, Tuple

import numpy as np

from .shapes import Cyl, Primitive

ROOM_ALBEDO = 0.7  # a neutral room's albedo: what "1" means in the room tint
NEAR_M = 0.2  # objects farther than this from a landmark are left to the room


@dataclass(frozen=True)
class Nearby:
    """What bounces light onto one landmark: its board, and nearby objects as spheres."""

    board_top_m: float
    board_reach_m: float
    board_tint: np.ndarray  # board albedo relative to the room (RGB)
    centres: np.ndarray  # (M, 3)
    radii: np.ndarray  # (M,)
    tints: np.ndarray  # (M, 3) albedo relative to the room


def _spheres(p: Primitive) -> Sequence[Tuple[np.ndarray, float, np.ndarray]]:
    """A primitive as one sphere per coloured part, each of its silhouette's area."""
    x0, x1, y0, y1, z0, z1 = p.extent()
    if isinstance(p, Cyl):
        tops = [*p.bounds[1:], p.y1]
        return [(np.array([p.x, 0.5 * (b + t), p.z]), float(np.sqrt(2 * p.r * (t - b) / np.pi)), c)
                for b, t, c in zip(p.bounds, tops, p.colours)]
    width = max(x1 - x0, z1 - z0)
    r = float(np.sqrt(width * (y1 - y0) / np.pi))
    return [(np.array([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2]), r, np.asarray(p.colour))]


def nearby(prims: Sequence[Primitive], landmarks: Sequence[int], floor_tint: np.ndarray
           ) -> Dict[int, Nearby]:
    """For every landmark primitive (by index), its :class:`Nearby` (by the landmark's id)."""
    out: Dict[int, Nearby] = {}
    start = 0
    for k in landmarks:
        lm = prims[k]
        assert isinstance(lm, Cyl)
        own = prims[start:k]
        start = k + 1
        below = [p for p in own if p.extent()[3] <= lm.y0 + 1e-6]  # tracks, chassis, board, mast
        boards = [p for p in below if not isinstance(p, Cyl) and p.extent()[3] > 0.03]
        if boards:
            b = max(boards, key=lambda p: p.extent()[3])
            x0, x1, _, top, z0, z1 = b.extent()
            reach = max(0.25 * ((x1 - x0) + (z1 - z0)) - lm.r, 0.0)
            tint = np.asarray(b.colour) / ROOM_ALBEDO
        else:
            top, reach, tint = 0.0, 0.0, np.asarray(floor_tint)
        skip = {id(p) for p in below} | {id(lm)}
        centres, radii, tints = [], [], []
        axis = np.array([lm.x, 0.5 * (lm.y0 + lm.y1), lm.z])
        for p in prims:
            if id(p) in skip:
                continue
            for c, r, colour in _spheres(p):
                if np.linalg.norm(c - axis) - r < NEAR_M:
                    centres.append(c)
                    radii.append(r)
                    tints.append(np.asarray(colour) / ROOM_ALBEDO)
        out[lm.ident] = Nearby(float(top), float(reach), tint, np.array(centres).reshape(-1, 3),
                               np.array(radii), np.array(tints).reshape(-1, 3))
    return out


def room_change(near: Nearby, normal: np.ndarray, point: np.ndarray, down: np.ndarray,
                room: np.ndarray) -> np.ndarray:
    """(K, 3) change of the room tint at landmark hits: board below, objects beside.

    ``down`` is the tint of the light from below (the floor's), ``room`` the tint
    each hit gets from the room as a whole (K, 3).
    """
    delta = np.zeros(point.shape)
    if near.board_reach_m > 0:
        dy = np.maximum(point[:, 1] - near.board_top_m, 1e-4)
        f = 0.5 * (1.0 - dy / np.sqrt(dy * dy + near.board_reach_m**2))
        delta += f[:, None] * (near.board_tint - down)
    if len(near.radii):
        to = near.centres[None] - point[:, None]  # (K, M, 3)
        dist = np.maximum(np.linalg.norm(to, axis=2), 1.2 * near.radii[None])
        cos = np.maximum(np.einsum("kmc,kc->km", to, normal) / dist, 0.0)
        f = np.minimum((near.radii[None] / dist) ** 2 * cos, 0.5)
        delta += np.einsum("km,mc->kc", f, near.tints) - f.sum(axis=1)[:, None] * room
    return delta


def fresnel(normal: np.ndarray, view: np.ndarray, f0: float = 0.04) -> np.ndarray:
    """Schlick's reflectance of a dielectric at each hit (K,): ``F₀ + (1 − F₀)(1 − n·v)⁵``."""
    c = np.clip(np.einsum("ij,ij->i", normal, view), 0.0, 1.0)
    return f0 + (1.0 - f0) * (1.0 - c) ** 5
