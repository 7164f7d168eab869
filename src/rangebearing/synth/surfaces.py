"""Floor materials with structure: wooden planks, tiles with grout, carpet pile.

Each pattern is an RGB albedo multiplier at floor points ``(x, z)``, seeded, and
anti-aliased: a seam or grout line narrower than the pixel's footprint on the
floor is drawn as the share of the footprint it covers (a box filter), and
grain finer than the footprint fades, so a floor seen at a grazing angle goes
to its mean instead of flickering.

``wood``   planks 8–20 cm wide, 0.5–1.5 m long, staggered, turned at a random
           angle; each plank its own tone (±20 %) and hue, grain stretched along
           it, dark 2 mm seams.
``tiles``  square tiles 0.2–0.6 m, each its own tone (±5 %), 3–8 mm grout lines
           darker or lighter than the tiles.
``carpet`` pile: strong fine-grained variation (±15 % at 3 mm) over slow blotches.

:func:`brick_gain` lays bricks in running bond over a wall.
"""

from __future__ import annotations

import math
from typing import Tuple

import numpy as np

from . import texture

PATTERNS = ("wood", "tiles", "carpet")
MORTAR = (0.62, 0.60, 0.56)


def _hash(a: np.ndarray, b: np.ndarray, seed: int) -> np.ndarray:
    """A fixed pseudo-random number in [0, 1) per integer pair."""
    v = np.sin(a * 12.9898 + b * 78.233 + seed * 0.618) * 43758.5453
    return v - np.floor(v)


def _line_cover(pos: np.ndarray, period: float, width: float, foot: np.ndarray) -> np.ndarray:
    """Share of a pixel footprint ``foot`` (centred at ``pos``) covered by lines of
    ``width`` repeating every ``period`` (centred on multiples of it)."""
    d = np.abs(pos - period * np.round(pos / period))
    f = np.maximum(foot, 1e-6)
    lo, hi = np.maximum(d - f / 2, -width / 2), np.minimum(d + f / 2, width / 2)
    return np.clip((hi - lo) / f, 0.0, 1.0)


def _fade(foot: np.ndarray, grain_m: float) -> np.ndarray:
    """How much of a pattern of ``grain_m`` survives a pixel footprint ``foot``
    (the footprint's average of it falls off as the footprint grows)."""
    return 1.0 / (1.0 + (foot / grain_m) ** 2)


def params(rng: np.random.Generator, kind: str) -> Tuple[float, ...]:
    """The pattern's draw: (size, length or grout width, angle, seam/grout factor)."""
    if kind == "wood":
        return (float(rng.uniform(0.08, 0.2)), float(rng.uniform(0.5, 1.5)),
                float(rng.uniform(0.0, math.pi)), float(rng.uniform(0.45, 0.7)))
    if kind == "tiles":
        grout = float(rng.uniform(0.55, 0.8)) if rng.random() < 0.7 else float(rng.uniform(1.2, 1.5))
        return (float(rng.uniform(0.2, 0.6)), float(rng.uniform(0.003, 0.008)),
                float(rng.uniform(0.0, math.pi / 2)), grout)
    if kind == "carpet":
        return (float(rng.uniform(0.1, 0.2)),)
    raise ValueError(f"unknown floor pattern {kind!r}")


def floor_gain(x: np.ndarray, z: np.ndarray, foot_x: np.ndarray, foot_z: np.ndarray, kind: str,
               p: Tuple[float, ...], seed: int) -> np.ndarray:
    """(K, 3) albedo multipliers of pattern ``kind`` (with :func:`params` ``p``) at floor
    points; ``foot_x``, ``foot_z`` are the pixel's footprint on the floor (m)."""
    foot = np.maximum(foot_x, foot_z)
    if kind == "carpet":
        fine = texture.pattern(x * 2.7, z * 2.7, seed + 7) * _fade(foot, 0.003)
        g = np.maximum(1.0 + p[0] * fine, 0.3)
        return np.repeat(g[:, None], 3, axis=1)
    c, s = math.cos(p[2]), math.sin(p[2])
    a, b = c * x + s * z, -s * x + c * z
    fa, fb = abs(c) * foot_x + abs(s) * foot_z, abs(s) * foot_x + abs(c) * foot_z
    if kind == "wood":
        width, length, _, seam = p
        k = np.floor(a / width)
        shift = _hash(k, k * 0.0, seed) * length
        m = np.floor((b + shift) / length)
        tone = 0.8 + 0.4 * _hash(k, m, seed + 1)
        hue = 0.06 * (_hash(k, m, seed + 2) - 0.5)
        grain = 0.08 * texture.pattern(a * 8.0, b * 0.4, seed + 3) * _fade(foot, 0.002)
        cover = np.maximum(_line_cover(a, width, 0.002, fa),
                           _line_cover(b + shift, length, 0.002, fb))
        g = (tone + grain) * (1.0 - (1.0 - seam) * cover)
        return np.stack([g * (1 + hue), g, g * (1 - hue)], axis=1)
    size, grout, _, shade = p
    tone = 0.95 + 0.1 * _hash(np.floor(a / size), np.floor(b / size), seed + 4)
    cover = np.maximum(_line_cover(a, size, grout, fa), _line_cover(b, size, grout, fb))
    g = tone * (1.0 - cover) + shade * cover
    return np.repeat(g[:, None], 3, axis=1)


def brick_gain(x: np.ndarray, y: np.ndarray, foot: np.ndarray, wall: Tuple[float, float, float],
               seed: int) -> np.ndarray:
    """(K, 3) albedo multipliers of a brick wall (running bond, 215 × 65 mm bricks, 10 mm
    mortar of :data:`MORTAR`) at wall points ``(x, y)``; ``foot`` is the pixel's footprint (m)."""
    course, length, joint = 0.075, 0.225, 0.01
    row = np.floor(y / course)
    shift = 0.5 * length * (row % 2)
    k = np.floor((x + shift) / length)
    tone = 0.8 + 0.4 * _hash(k, row, seed)
    hue = 0.08 * (_hash(k, row, seed + 1) - 0.5)
    cover = np.maximum(_line_cover(y, course, joint, foot), _line_cover(x + shift, length, joint, foot))
    mortar = np.asarray(MORTAR) / np.maximum(np.asarray(wall), 0.02)
    brick = np.stack([tone * (1 + hue), tone, tone * (1 - hue)], axis=1)
    return brick * (1.0 - cover[:, None]) + mortar[None] * cover[:, None]
