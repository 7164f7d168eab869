"""Procedural surface texture: a smooth, seeded albedo pattern for floors and walls.

Value noise in four octaves (lattice spacings 0.3 m down to 16 mm, amplitude
falling with spacing), baked once per seed into a 4 m × 4 m tile at 8 mm and
sampled bilinearly, scaled to unit standard deviation. Beyond the tile the
pattern mirrors.
"""

from __future__ import annotations

import functools

import cv2
import numpy as np

SPACINGS_M = (0.3, 0.1, 0.04, 0.016)
TILE_M = 4.0
PIXEL_M = 0.008
ORIGIN_M = (-2.0, 0.0)  # (u, v) of the tile's first texel: the floor in front of the camera


@functools.lru_cache(maxsize=16)
def _tile(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n = round(TILE_M / PIXEL_M)
    out = np.zeros((n, n), np.float32)
    for spacing in SPACINGS_M:
        cells = max(round(TILE_M / spacing), 2)
        grid = rng.uniform(-1.0, 1.0, (cells, cells)).astype(np.float32)
        out += (spacing / SPACINGS_M[0]) ** 0.3 * cv2.resize(grid, (n, n), interpolation=cv2.INTER_CUBIC)
    out -= out.mean()
    out /= out.std()
    out.setflags(write=False)
    return out


def pattern(u: np.ndarray, v: np.ndarray, seed: int) -> np.ndarray:
    """The seed's pattern at surface coordinates ``(u, v)`` in metres: zero mean, unit std."""
    tile = _tile(seed)
    n = int(np.size(u))
    rows = -(-n // 1024)  # cv2.remap wants both sides under 32767
    maps = np.zeros((2, rows * 1024), np.float32)
    maps[0, :n] = (np.ravel(u) - ORIGIN_M[0]) / PIXEL_M
    maps[1, :n] = (np.ravel(v) - ORIGIN_M[1]) / PIXEL_M
    out = cv2.remap(tile, maps[0].reshape(rows, 1024), maps[1].reshape(rows, 1024), cv2.INTER_LINEAR,
                    borderMode=cv2.BORDER_REFLECT_101)
    return out.ravel()[:n].reshape(np.shape(u)).astype(np.float64)


def factor(u: np.ndarray, v: np.ndarray, seed: int, amount: float) -> np.ndarray:
    """Albedo multiplier ``1 + amount·pattern``, kept positive."""
    return np.maximum(1.0 + amount * pattern(u, v, seed), 0.05)
