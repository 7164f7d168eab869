"""Procedural surface texture: a smooth, seeded albedo pattern for floors and walls.

Value noise in five octaves (lattice spacings 0.3 m down to 3 mm, each a
smoothstep-interpolated grid of hashed random values, amplitude falling with
spacing), scaled to unit standard deviation. Far away the finest octaves
average out within a pixel, as a carpet's grain does; near the camera they show.
"""

from __future__ import annotations

import numpy as np

SPACINGS_M = (0.3, 0.1, 0.03, 0.01, 0.003)
_AMPS = np.array([(s / SPACINGS_M[0]) ** 0.3 for s in SPACINGS_M])
_NORM = 1.0 / np.sqrt((_AMPS**2).sum() * (1.0 / 3.0) * 0.55)  # value noise std ≈ 0.55/√3 per octave
_K1, _K2, _K3 = np.uint64(0x9E3779B97F4A7C15), np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB)


def _hash(i: np.ndarray, j: np.ndarray, seed: int) -> np.ndarray:
    """Uniform values in [-1, 1] at integer lattice points (i, j), fixed by the seed."""
    k = i.astype(np.int64).view(np.uint64) * _K1 + j.astype(np.int64).view(np.uint64) * _K2
    k = k + np.array([seed & 0xFFFFFFFF], dtype=np.uint64) * _K3
    k ^= k >> np.uint64(31)
    k *= _K2
    k ^= k >> np.uint64(29)
    return (k >> np.uint64(11)).astype(np.float64) / 2.0**52 - 1.0


def pattern(u: np.ndarray, v: np.ndarray, seed: int) -> np.ndarray:
    """The seed's pattern at surface coordinates ``(u, v)`` in metres: zero mean, std ≈ 1."""
    out = np.zeros(np.shape(u))
    for octave, (spacing, amp) in enumerate(zip(SPACINGS_M, _AMPS)):
        x, y = np.asarray(u) / spacing, np.asarray(v) / spacing
        i, j = np.floor(x), np.floor(y)
        fx, fy = x - i, y - j
        sx, sy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)
        s = seed * 7 + octave
        a, b = _hash(i, j, s), _hash(i + 1, j, s)
        c, e = _hash(i, j + 1, s), _hash(i + 1, j + 1, s)
        out += amp * ((a + (b - a) * sx) * (1 - sy) + (c + (e - c) * sx) * sy)
    return out * _NORM


def factor(u: np.ndarray, v: np.ndarray, seed: int, amount: float) -> np.ndarray:
    """Albedo multiplier ``1 + amount·pattern``, kept positive."""
    return np.maximum(1.0 + amount * pattern(u, v, seed), 0.05)
