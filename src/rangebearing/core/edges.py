"""Sub-pixel band edges in linear light: where each band starts and ends, row by row and column by column.

In linear light a pixel straddling an edge is the coverage-weighted mix of its two sides, so any channel
combination is linear in coverage. The excess ``R − (G+B)/2`` (red) or ``B − (R+G)/2`` (blue) is the paint's
level inside a band and the background's level outside it, and the edge between two rows ``a`` (inside) and
``b`` (outside) lies at::

    edge = (a − ½) + Σ_{y=a..b} (p(y) − bg) / (level − bg)      (going down)

for any symmetric blur: the two-level integral. A band's centre is the mean of its two edges when both are its
own; when its outer edge merges with a background of its colour (``level − bg`` small), the inner edge and the
white body's height place it instead, since on the cylinder's near surface heights map linearly to rows. The
sRGB-like encoding is undone with a 2.2 power.
"""

from __future__ import annotations

import functools
import math
from typing import Optional, Tuple

import cv2
import numpy as np

from .._compat import frozen
from .color import Gains

GAMMA = 2.2
BG_ROWS = 4  # rows averaged for a background level
STEP_MIN, STEP_SHARE, STEP_NOISE = 0.02, 0.3, 0.0015  # see step_floor
RHO_MAX = 0.8  # the columns' lag-1 error correlation counted at most (_column_sigma; from ~10-40 columns)
MERGE_CONTRAST = 0.5  # an outer edge whose level step is below this share of the band's level is merged


@functools.lru_cache(maxsize=2)
def linear_table(gamma: float = GAMMA) -> np.ndarray:
    """(256,) float32: 8-bit encoded value → linear light in [0, 1]."""
    return (np.arange(256, dtype=np.float32) / 255.0) ** np.float32(gamma)


def excess(tile: np.ndarray, gains: Gains) -> Tuple[np.ndarray, np.ndarray]:
    """Red and blue excess ``(H, W)`` float32 of a BGR uint8 tile, balanced, in linear light."""
    if tile.size == 0 or tile.ndim != 3:
        lin = linear_table()[tile]
        b, g, r = lin[..., 0], lin[..., 1], lin[..., 2]
    else:  # the same values: a table lookup and contiguous planes are several times cheaper than strided channels
        b, g, r = np.ascontiguousarray(cv2.LUT(tile, linear_table().reshape(256, 1)).transpose(2, 0, 1))
    b, g, r = b * gains[0], g * gains[1], r * gains[2]
    return r - 0.5 * (g + b), b - 0.5 * (r + g)


# BT.601's luma weights (B, G, R): a chroma change that keeps a pixel's luma Y' (colour denoise, 4:2:0)
# changes this sum of the linear channels only to second order where the pixel is neutral (the white body)
LUMA_WEIGHTS = (0.114, 0.587, 0.299)


def excess_luma(tile: np.ndarray, gains: Gains) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`excess` of a BGR uint8 tile and its luma in linear light ``(H, W)`` float32 (unbalanced)."""
    if tile.size == 0 or tile.ndim != 3:
        lin = linear_table()[tile]
        b, g, r = lin[..., 0], lin[..., 1], lin[..., 2]
    else:
        b, g, r = np.ascontiguousarray(cv2.LUT(tile, linear_table().reshape(256, 1)).transpose(2, 0, 1))
    wb, wg, wr = (np.float32(v) for v in LUMA_WEIGHTS)
    luma = wb * b + wg * g + wr * r
    b, g, r = b * gains[0], g * gains[1], r * gains[2]
    return r - 0.5 * (g + b), b - 0.5 * (r + g), luma


def _mean(x: np.ndarray) -> float:
    """``float(x.mean())`` of a float32 array, bit for bit, without ``np.mean``'s overhead (it runs per band)."""
    return float(np.float32(float(np.add.reduce(x)) / x.size))


def mean_along(a: np.ndarray, axis: int) -> np.ndarray:
    """``a.mean(axis=axis)`` of a 2-D float32 array, bit for bit (the same sum, divided by the same
    count in the same way), without ``np.mean``'s Python layer (it runs several times per band)."""
    s = np.add.reduce(a, axis=axis)
    return np.true_divide(s, np.intp(a.shape[axis]), out=s, casting="unsafe")


def edge_down(p: np.ndarray, a: int, b: int, level: float, bg: float) -> float:
    """Edge between row ``a`` (inside, level ``level``) and row ``b`` > a (outside, ``bg``) of profile ``p``."""
    return (a - 0.5) + float(np.add.reduce(p[a : b + 1] - bg)) / (level - bg)


def edge_up(p: np.ndarray, a: int, b: int, level: float, bg: float) -> float:
    """Edge between row ``a`` (inside) and row ``b`` < a (outside) of profile ``p``, going up."""
    return (a + 0.5) - float(np.add.reduce(p[b : a + 1] - bg)) / (level - bg)


@frozen
class BandEdges:
    """One band's rows: centre, inner edge and the spread of its per-column centres (tile pixels)."""

    centre: float
    inner: float
    merged: bool
    sigma: float  # one-sigma uncertainty of ``centre`` from the column-to-column scatter
    scatter: Optional[Tuple[float, float, int, int]] = None  # what measures ``sigma``: level, bg, mid, end rows


def band_rows(
    p2d: np.ndarray, top: int, bottom: int, inner_down: bool, white_end: int, outer_end: int,
    p: Optional[np.ndarray] = None, column_sigma: bool = True,
) -> Optional[BandEdges]:
    """Measure one band in a (rows, cols) excess array whose rows ``top..bottom`` are its expected rows.

    ``inner_down``: the inner (white) edge is below the band (red); otherwise above (blue).
    ``white_end`` is the row in the white body where the inner integral stops; ``outer_end`` the
    last background row beyond the outer edge (clipped to the array). ``p`` is ``p2d.mean(axis=1)``
    when the caller has it already. ``column_sigma=False``: ``sigma`` is NaN, not measured.
    """
    p = mean_along(p2d, 1) if p is None else p
    n = len(p)
    top, bottom = max(0, top), min(n - 1, bottom)
    core_lo, core_hi = top + (bottom - top) // 4, bottom - (bottom - top) // 4
    if core_hi < core_lo:
        return None
    mid = (core_lo + core_hi) // 2
    level = _mean(p[core_lo : core_hi + 1])
    white_end = min(n - 1, max(0, white_end))
    outer_end = min(n - 1, max(0, outer_end))
    w_bg = _level_beyond(p, white_end, inner_down)
    # no paint's excess, or no colour step at the white body: not a band (with level > 0 the outer step
    # below is either merged or at least half the level, so neither edge divides by zero)
    if not level > 0.0 or level - w_bg <= step_floor(level):
        return None
    if inner_down:
        inner = edge_down(p, mid, white_end, level, w_bg)
        o_bg = _level_beyond(p, outer_end, False) if outer_end < mid else level
        merged = outer_end >= mid or level - o_bg < MERGE_CONTRAST * level
        outer = inner if merged else edge_up(p, mid - 1, outer_end, level, o_bg)
    else:
        inner = edge_up(p, mid, white_end, level, w_bg)
        o_bg = _level_beyond(p, outer_end, True) if outer_end > mid else level
        merged = outer_end <= mid or level - o_bg < MERGE_CONTRAST * level
        outer = inner if merged else edge_down(p, mid + 1, outer_end, level, o_bg)
    centre = 0.5 * (inner + outer)
    sigma = _column_sigma(p2d, level, w_bg, mid, white_end, inner_down) if column_sigma else float("nan")
    return BandEdges(centre, inner, merged, sigma, (level, w_bg, mid, white_end))


def step_floor(level: float) -> float:
    """The smallest colour step at the white body that makes a band: 0.02 in linear light, less for
    a dark band (dim light, a backlit landmark), down to 30 % of its own level but not into the noise.

    The noise floor is in linear light, where the tone curve's slope shrinks a dark pixel's noise with
    its level: in a frame 2 stops under (band at V ~25) a band steps ~0.005 from the body and the
    column-mean profile's noise is ~0.0005 a row, so the floor (``STEP_NOISE``) is three times that."""
    return min(STEP_MIN, max(STEP_NOISE, STEP_SHARE * level))


def _level_beyond(p: np.ndarray, row: int, down: bool, rows: int = BG_ROWS) -> float:
    """Mean of ``p`` over ``rows`` rows from ``row`` on, away from the band: one row is too noisy
    (its error is multiplied by every row of the integral)."""
    seg = p[row : row + rows] if down else p[max(0, row - rows + 1) : row + 1]
    return _mean(seg) if seg.size else float(p[row])


def _column_sigma(p2d: np.ndarray, level: float, bg: float, mid: int, end: int, down: bool) -> float:
    """Standard error of the inner edge from the scatter of the per-column edges (rows).

    Each column's edge is its own two-level integral (its own band level and background: shading across the
    cylinder and the profile's weighting of the end columns scale a column, they do not move its edge), and the
    scatter is taken about a parabola through them: seen from below or above the band, an edge is an arc of an
    ellipse, a smooth curve that is no noise. Neighbouring columns' errors correlate (lag-1 ``ρ`` of the
    residuals) where the camera mixes pixels across them (demosaic, chroma subsampling, denoise, video blocks).
    """
    lo, hi = (mid, end) if down else (end, mid)
    beyond = p2d[end : end + BG_ROWS] if down else p2d[max(0, end - BG_ROWS + 1) : end + 1]
    lev = mean_along(p2d[max(0, mid - 1) : mid + 2], 0)
    bgc = mean_along(beyond, 0) if beyond.size else np.full(p2d.shape[1], bg, np.float32)
    step = lev - bgc
    ok = step > 0.5 * (level - bg)
    idx = np.flatnonzero(ok)
    cols = len(idx)
    if cols < 5:
        return 0.5
    sums = np.add.reduce(p2d[lo : hi + 1, ok] - bgc[ok], axis=0) / step[ok]
    a, aa = _curve_basis(idx.tobytes())
    res = sums - np.float32(np.add.reduce(sums) / np.intp(cols)) - (a @ sums / aa) @ a
    rho = min(RHO_MAX, max(-RHO_MAX, float(res[:-1] @ res[1:]) / max(float(res @ res), 1e-30)))  # (1+ρ)/(1−ρ): the
    return math.sqrt(float(res @ res) / (cols - 3) * (1.0 + rho) / (1.0 - rho)) / math.sqrt(cols)  # mean's variance


@functools.lru_cache(maxsize=512)
def _curve_basis(columns: bytes) -> Tuple[np.ndarray, np.ndarray]:
    """``(a, a·a)`` of :func:`_column_sigma` for the columns (``np.intp`` indices, as bytes): the centred column
    and the parabola orthogonal to it and to the constant, and their squared norms.

    They depend on which columns took part only, and nearly every band of a landmark seen whole
    has all of its columns: one computation serves them all (the same arithmetic, so the same values).
    """
    x = np.frombuffer(columns, np.intp).astype(np.float64)
    x -= np.add.reduce(x) / len(x)
    x2 = x * x
    x2 -= np.add.reduce(x2) / len(x)
    a = np.empty((2, len(x)))
    a[0] = x
    a[1] = x2 - x * (x @ x2) / (x @ x)  # orthogonal to each other and to the constant
    a.flags.writeable = False
    aa = np.einsum("ij,ij->i", a, a)
    aa.flags.writeable = False
    return a, aa


LUMA_REACH_PX = 4  # rows past a band's chroma edge that its luma edge is integrated over
LUMA_STEP = 0.25  # the luma step at an edge must reach this share of the brighter side's luma
BLEED_PX = 2.0  # how far either way a luma inner edge may lie from the chroma one, at the least
OUTER_BLEED_PX = 2.0  # ... and a luma outer edge, either way
LUMA_RING = 0.1  # luma beyond both levels by this share of the step beside an edge: the camera sharpens


def luma_edge(p: np.ndarray, edge: float, down: bool, band_px: float, inner: bool) -> Optional[float]:
    """One band edge on the luma profile ``p``, near its chroma edge ``edge`` (profile rows), or
    ``None`` when the luma shows no clear step there or the two edges lie too far apart.

    ``down``: the band lies above the edge (the red band's inner edge, the blue band's outer
    one). ``inner``: the edge is the band's own with the white body, which is brighter.

    Luma keeps full resolution through colour denoise and 4:2:0 chroma, which bleed a band's
    colour across its edges, the more in linear light the brighter the other side: into the
    white body always (the chroma edge moves into it by up to a pixel or two: L short, range
    2-5 % long on such a camera; 3-4 px under video coding), into a light background too. Coarse
    coding (MJPEG, video blocks) and lateral colour move the chroma edge the other way as well,
    into the band. An inner luma edge is taken when it lies within 2 px of the chroma one, or
    farther but short of the middle of the band as ``band_px`` (the chroma's) spans it, either
    way; an outer one within 2 px either way, when the background's luma differs from the
    band's. Otherwise (a background of the band's luma) the chroma edge stands. A luma step
    from a shadow or a part in front of the body within that reach is left to the caller: it
    spoils the landmark's proportions (:func:`.measure._rows`).

    The luma edge is the two-level integral, unless the luma beside it overshoots either level
    by more than ``LUMA_RING`` of the step: a camera's sharpening puts a bright lobe on one side
    and a dark one on the other, which move the levels and, unless both lie wholly inside the
    window, the integral; the half-level crossing stays where the edge is (the clean renders do not ring).
    """
    n = len(p)
    s = 1 if down else -1
    d_in = max(1.0, min(0.5 * band_px, float(LUMA_REACH_PX)))
    a = round(edge - s * d_in)  # inside the band
    z = round(edge + s * LUMA_REACH_PX)  # beyond the edge
    core = p[max(0, a - 1) : a + 2] if 0 <= a < n else p[0:0]
    beyond = p[z : z + BG_ROWS] if down else p[max(0, z - BG_ROWS + 1) : z + 1]
    if not 0 <= z < n or core.size == 0 or beyond.size < BG_ROWS:
        return None
    level, other = _mean(core), _mean(beyond)
    step = other - level if inner else abs(other - level)
    if not step > LUMA_STEP * max(other, level):
        return None
    seg = p[min(a, z) : max(a, z) + 1]
    ring = max(float(seg.max()) - max(level, other), min(level, other) - float(seg.min()))
    if ring > LUMA_RING * abs(other - level):  # sharpened: the lobes beside the edge bias the integral
        found = _crossing(p, a, z, 0.5 * (level + other))
    else:
        found = edge_down(p, a, z, level, other) if down else edge_up(p, a, z, level, other)
    if found is None:
        return None
    shift = s * (edge - found)  # towards the band
    # an inner edge may lie anywhere the chroma bled over or drew back from, short of the band's middle
    reach = max(BLEED_PX, 0.5 * band_px - 0.5) if inner else OUTER_BLEED_PX
    return found if -reach <= shift <= reach else None


def _crossing(p: np.ndarray, a: int, z: int, half: float) -> Optional[float]:
    """Where profile ``p`` first crosses ``half`` going from row ``a`` towards row ``z`` (linear between
    rows; ``None`` if it never does). A step between rows k and k+1 crosses at k + ½, where the
    two-level integral puts it."""
    s = 1 if z > a else -1
    inside = bool(p[a] < half)
    for k in range(a, z, s):
        if bool(p[k + s] < half) != inside:
            return k + s * float((half - p[k]) / (p[k + s] - p[k]))
    return None


def luma_inner(p: np.ndarray, edge: float, down: bool, band_px: float) -> Optional[float]:
    """:func:`luma_edge` of a band's inner edge (``down``: the white body lies below it)."""
    return luma_edge(p, edge, down, band_px, True)
