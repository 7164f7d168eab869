"""The primitives the ray caster knows, and the per-ray hit buffers.

Ids: every primitive owns a block of :data:`PARTS` consecutive ids starting at
``ident``; a landmark's are ``+0`` blue band, ``+1`` white body, ``+2`` red
band, ``+14`` bottom cap, ``+15`` top cap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Tuple, Union

import numpy as np

ID_BACKGROUND, ID_WALL, ID_FLOOR = 0, 1, 2
ID_PATCH, ID_POSTER, ID_OBJECT = 16, 256, 1024
PARTS = 16  # ids per object
Extent = Tuple[float, float, float, float, float, float]  # x0, x1, y0, y1, z0, z1


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

    @classmethod
    def empty(cls, shape: Tuple[int, ...]) -> Hits:
        """Nothing hit yet: infinite depth, id -1, black."""
        return cls(np.full(shape, np.inf), np.full(shape, -1, np.int32), np.zeros((*shape, 3)))


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
    glossy: bool = False

    def extent(self) -> Extent:
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

    def extent(self) -> Extent:
        return self.x0, self.x1, self.y0, self.y1, self.z0, self.z1


@dataclass(frozen=True)
class OBox:
    """A box turned about the vertical: centre ``(x, z)``, half-sizes along its heading
    ``(cos ψ, 0, sin ψ)`` and across it ``(−sin ψ, 0, cos ψ)``."""

    x: float
    z: float
    half_long: float
    half_across: float
    y0: float
    y1: float
    heading: float
    colour: np.ndarray
    ident: int

    @property
    def axes(self) -> Tuple[np.ndarray, np.ndarray]:
        c, s = math.cos(self.heading), math.sin(self.heading)
        return np.array([c, 0.0, s]), np.array([-s, 0.0, c])

    def extent(self) -> Extent:
        c, s = abs(math.cos(self.heading)), abs(math.sin(self.heading))
        ex = c * self.half_long + s * self.half_across
        ez = s * self.half_long + c * self.half_across
        return self.x - ex, self.x + ex, self.y0, self.y1, self.z - ez, self.z + ez


Primitive = Union[Cyl, Cuboid, OBox]
