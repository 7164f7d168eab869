"""Sub-pixel band centroids from the unfiltered pixels, all bands of a frame in one batch.

Each band's region (its blob's box grown by a margin, area-averaged to 1/f
resolution when the band is tall) is copied into one zero-padded tile of a
stack; colour conversion, weights and first-order moments then run once over
the whole stack, so a tenth landmark costs a copy, not another round of calls.
Black padding has no hue and weighs nothing.
"""

from __future__ import annotations

from typing import List, Optional, Sequence, Tuple

import cv2
import numpy as np

from .._compat import frozen
from .color import CLIPPED, CLIPPED_HUE_S_MIN, Gains, apply_gains, class_hues, ramp_table, to_hsv
from .params import DetectionParams
from .types import XY, BBox

# Bands taller than this (full-resolution pixels) are measured at 1/f resolution,
# so every band costs about the same whatever its range; a band still spans at
# least REFINE_BAND_PX / 2 rows, ample for sub-pixel moments.
REFINE_BAND_PX = 8
S_RAMP = 40  # saturation ramp half-width for the horizontal weights
CHROMA_FLOOR = 0.15  # share of a band's mean chroma where its vertical weight starts
DARK_SHARE = 0.3  # pixels darker than this share of the band's mean V are not band (shading stays above)


def band_weights(
    hsv: np.ndarray, n_red: int, cfg: DetectionParams, refs: Optional[np.ndarray] = None
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weights ``(w_x, w_y)`` of a stack of band tiles, each (N, H, W): ``w_x`` uint8 0–255, ``w_y`` float32 0–1.

    Parameters
    ----------
    hsv : (N, H, W, 3) uint8
        HSV tiles, one band each.
    n_red : int
        The first ``n_red`` tiles hold red bands, the rest blue ones.
    refs : (N,) float array, optional
        Each band's mean chroma if already known (tracking keeps it from the
        last full scan); otherwise measured here.

    Returns
    -------
    w_x, w_y, refs
        The weights and each band's mean chroma.

    Notes
    -----
    Both weights are zero outside the band's hue ranges and for pixels darker
    than 10; ``w_y`` also for pixels darker than 30 % of the band's mean V (a
    dark, faintly tinted pedestal below the band; a shaded side stays above it).
    Clipped pixels (V ≥ 250) get full ``w_x``: a highlight keeps its hue.

    ``w_x`` weighs by saturation on a linear ramp from ``s_min − 40`` (0) to
    ``s_min + 40`` (255). Saturation does not depend on brightness, so shading
    across the cylinder does not pull the *horizontal* centroid.

    ``w_y`` weighs by chroma (max − min channel = S·V/255) on a ramp from 15 %
    of the band's mean chroma (0) to its mean (1): faint chroma noise of
    neutral pixels weighs nothing and the band's core is flat. Chroma is linear in
    the share of a pixel the band covers whether the neighbour is the white body
    or the dark robot below, so the *vertical* centroid, and with it L, is
    unbiased; saturation would count a blue/black edge pixel as fully blue.
    """
    n, h, w = hsv.shape[:3]
    hue, sat, val = cv2.split(hsv.reshape(n * h, w, 3))
    gate = np.empty_like(hue)
    split = n_red * h
    clip = cv2.threshold(val, CLIPPED - 1, 255, cv2.THRESH_BINARY)[1]
    # the clipped pixels whose hue may lie wider (:func:`.color.clip_of`, :func:`.color.clipped_hue_tables`)
    wide = cv2.bitwise_and(clip, cv2.threshold(sat, CLIPPED_HUE_S_MIN - 1, 255, cv2.THRESH_BINARY)[1])
    if split:
        gate[:split] = class_hues(hue[:split], cfg.red_hue, cfg.blue_hue, wide[:split])[0]
    if split < n * h:
        gate[split:] = class_hues(hue[split:], cfg.red_hue, cfg.blue_hue, wide[split:])[1]
    # :func:`.color.sv_gate` at S ≥ 1, V ≥ min(v_min, 10): (S ≥ 1 or V clipped) and V ≥ that floor (a clipped
    # V is above it), in three thresholds instead of four, the clipped one kept for ``w_x``
    lit = cv2.threshold(val, min(cfg.v_min, 10) - 1, 255, cv2.THRESH_BINARY)[1]
    gate = cv2.bitwise_and(gate, cv2.bitwise_and(cv2.max(cv2.threshold(sat, 0, 255, cv2.THRESH_BINARY)[1], clip), lit))
    core = cv2.bitwise_and(gate, cv2.threshold(sat, cfg.s_min - 1, 255, cv2.THRESH_BINARY)[1])
    count = np.maximum(_tile_sums(core, n) / 255.0, 1.0)
    # brightness relative to the band: a dark, faintly tinted pedestal or shadow next to it is no band
    v_ref = _tile_sums(cv2.bitwise_and(val, core), n) / count
    # V ≥ 0.3·v_ref for an integer V is V ≥ ceil(0.3·v_ref): a uint8 comparison, not a float64 one
    v_least = np.ceil(DARK_SHARE * v_ref).astype(np.uint8)[:, None]
    v_gate = np.multiply(val.reshape(n, -1) >= v_least, np.uint8(255), dtype=np.uint8).reshape(n * h, w)
    w_x = cv2.LUT(sat, ramp_table(max(0, cfg.s_min - S_RAMP), 2 * S_RAMP))
    # a clipped highlight (a spotlight's vertical streak) keeps its hue but loses saturation: full weight
    w_x = cv2.bitwise_and(cv2.max(w_x, clip), gate)
    # only rows need the brightness gate (a pedestal lies below the band; the dark limb must stay for x)
    chroma = cv2.bitwise_and(cv2.multiply(sat, val, scale=1.0 / 255.0), cv2.bitwise_and(gate, v_gate))
    if refs is None:
        refs = _tile_sums(cv2.bitwise_and(chroma, core), n) / count
    ref = np.asarray(refs, np.float32).reshape(n, 1)
    floor = np.float32(CHROMA_FLOOR) * ref
    w_y = chroma.reshape(n, h * w).astype(np.float32)
    w_y -= floor
    w_y /= np.maximum(ref - floor, np.float32(1e-3))  # a tile with no core has ref 0 and weighs nothing
    np.maximum(w_y, np.float32(0.0), out=w_y)  # np.clip's values, without its Python layer;
    np.minimum(w_y, np.float32(1.0), out=w_y)  # outside the gate chroma is 0, so the weight is 0
    return w_x.reshape(n, h, w), w_y.reshape(n, h, w), ref[:, 0]


def _tile_sums(a: np.ndarray, n: int) -> np.ndarray:
    """(N,) int32 sums of each of the ``n`` tiles stacked in the uint8 image ``a`` (exact; OpenCV's reduction is
    ~10× faster than numpy's uint8 → int64 one)."""
    return cv2.reduce(a.reshape(n, -1), 1, cv2.REDUCE_SUM, dtype=cv2.CV_32S)[:, 0]


def tile_centroids(w_x: np.ndarray, w_y: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per-tile ``(x, y, mass_x, ok)``: x from ``w_x``, y from ``w_y`` (first-order moments)."""
    cols = w_x.sum(axis=1, dtype=np.float32)  # (N, W)
    rows = w_y.sum(axis=2, dtype=np.float32)  # (N, H)
    m_x, m_y = cols.sum(axis=1), rows.sum(axis=1)
    ok = (m_x > 1e-3) & (m_y > 1e-3)
    x = cols @ np.arange(cols.shape[1], dtype=np.float32) / np.maximum(m_x, 1e-3)
    y = rows @ np.arange(rows.shape[1], dtype=np.float32) / np.maximum(m_y, 1e-3)
    return x, y, m_x, ok


Margin = Tuple[int, int]  # grow a band's box by (x, y) pixels on each side


def half_or_area(f: int) -> int:
    """The OpenCV interpolation for an f-fold area average: at exactly ½ bilinear
    samples each 2×2 block's centre, which is the same average, computed faster."""
    return cv2.INTER_LINEAR if f == 2 else cv2.INTER_AREA


class Pyramid:
    """Area-averaged copies of one frame at ½, ¼, ⅛, made on demand and kept for the frame.

    Level f holds the means of the frame's f×f blocks on a grid fixed to the
    frame, so a crop of it equals an area-resize of the same region.
    """

    def __init__(self, bgr: np.ndarray, half: Optional[np.ndarray] = None) -> None:
        self._levels = {1: bgr}
        if half is not None:
            self._levels[2] = half

    def level(self, f: int) -> np.ndarray:
        if f not in self._levels:
            finer = self.level(f // 2)
            h, w = finer.shape[:2]
            self._levels[f] = cv2.resize(
                finer[: h // 2 * 2, : w // 2 * 2], (w // 2, h // 2), interpolation=cv2.INTER_LINEAR
            )
        return self._levels[f]


@frozen
class BandFix:
    """One band measured on the unfiltered pixels.

    ``mass_px`` is the band's weight (saturation ramp) in full-resolution
    pixels: about its visible area, used to tell a tracked band from clutter.
    """

    xy_px: XY
    mass_px: float
    chroma_ref: float  # the band's mean chroma (S·V/255), the scale of its vertical weights


def _band_region(shape: Tuple[int, ...], bbox: BBox, margin: Margin) -> Tuple[int, int, int, int, int]:
    """``(x0, y0, x1, y1, f)``: the band's grown box, trimmed to a multiple of its scale ``f``."""
    h, w = shape[:2]
    bx, by, bw, bh = bbox
    mx, my = margin
    k = bh // REFINE_BAND_PX
    f = 1 if k < 2 else 2 if k < 4 else 4 if k < 8 else 8
    # Downscaled pixels sit on a grid fixed to the frame, so a band gives the same
    # weights whatever box it is measured in (tracking windows and full scans agree).
    x0, y0 = max(0, bx - mx) // f * f, max(0, by - my) // f * f
    x1, y1 = min(w, bx + bw + mx), min(h, by + bh + my)
    return x0, y0, x0 + max(f, (x1 - x0) // f * f), y0 + max(f, (y1 - y0) // f * f), f


def _blank_neighbours(
    stack: np.ndarray, regions: Sequence[Tuple[int, int, int, int, int]], boxes: Sequence[BBox], is_red: Sequence[bool]
) -> None:
    """Black out, in each tile, the other bands of its colour that reach into it.

    Landmarks side by side put each other's bands inside their measuring
    windows; a neighbour's band would pull the centroid towards it.
    """
    n_red = sum(1 for r in is_red if r)
    if n_red < 2 and len(is_red) - n_red < 2:  # no two bands of one colour: nothing to blank
        return
    b = np.asarray(boxes, np.int64)
    bx0, by0 = b[:, 0] - 1, b[:, 1] - 1
    bx1, by1 = b[:, 0] + b[:, 2] + 1, b[:, 1] + b[:, 3] + 1
    r = np.asarray([reg[:4] for reg in regions], np.int64)
    red = np.asarray(is_red, bool)
    hit = (
        (bx0[None, :] < r[:, 2:3])
        & (bx1[None, :] > r[:, 0:1])
        & (by0[None, :] < r[:, 3:4])
        & (by1[None, :] > r[:, 1:2])
        & (red[None, :] == red[:, None])
    )
    np.fill_diagonal(hit, False)
    for j, i in zip(*np.nonzero(hit)):
        x0, y0, _, _, f = regions[j]
        stack[
            j,
            max(0, (by0[i] - y0) // f) : max(0, -(-(by1[i] - y0) // f)),
            max(0, (bx0[i] - x0) // f) : max(0, -(-(bx1[i] - x0) // f)),
        ] = 0


def measure_bands(
    bgr: np.ndarray,
    boxes: Sequence[BBox],
    is_red: Sequence[bool],
    margins: Sequence[Margin],
    cfg: DetectionParams,
    gains: Gains,
    pyramid: Optional[Pyramid] = None,
    refs: Optional[Sequence[float]] = None,
) -> List[Optional[BandFix]]:
    """Measure each band inside its box grown by its margin; ``None`` where nothing of its colour is left.

    Parameters
    ----------
    bgr : (H, W, 3) uint8
        The full-resolution frame.
    boxes, is_red, margins : sequences of equal length
        Each band's box (x, y, w, h) in full-resolution pixels, its colour, and
        how far to grow the box on each side.
    pyramid : Pyramid, optional
        Downscaled copies of the frame to crop tall bands from; without it each
        tall band's region is resized on its own (the same pixels either way).
    refs : sequence of float, optional
        Each band's mean chroma when known (see :func:`band_weights`).

    Returns
    -------
    list of BandFix or None
        Centroids in full-resolution pixels (pixel centres at integers).
    """
    if not boxes:
        return []
    order = [k for k, red in enumerate(is_red) if red] + [k for k, red in enumerate(is_red) if not red]
    regions = [_band_region(bgr.shape, boxes[k], margins[k]) for k in order]
    crops = []
    for x0, y0, x1, y1, f in regions:
        if f == 1:
            crops.append(bgr[y0:y1, x0:x1])
        elif pyramid is not None:
            crops.append(pyramid.level(f)[y0 // f : y1 // f, x0 // f : x1 // f])
        else:
            roi = bgr[y0:y1, x0:x1]
            crops.append(cv2.resize(roi, ((x1 - x0) // f, (y1 - y0) // f), interpolation=half_or_area(f)))
    th = max(c.shape[0] for c in crops)
    tw = max(c.shape[1] for c in crops)
    stack = np.zeros((len(crops), th, tw, 3), np.uint8)
    for tile, crop in zip(stack, crops):
        tile[: crop.shape[0], : crop.shape[1]] = crop
    _blank_neighbours(stack, regions, [boxes[k] for k in order], [is_red[k] for k in order])
    hsv = to_hsv(apply_gains(stack.reshape(-1, tw, 3), gains)).reshape(stack.shape)
    ordered_refs = None if refs is None else np.asarray(refs, np.float32)[order]
    w_x, w_y, band_refs = band_weights(hsv, sum(1 for r in is_red if r), cfg, ordered_refs)
    x, y, mass, ok = tile_centroids(w_x, w_y)
    out: List[Optional[BandFix]] = [None] * len(boxes)
    for j, (k, (x0, y0, _, _, f)) in enumerate(zip(order, regions)):
        if ok[j]:
            xy = (x0 + (float(x[j]) + 0.5) * f - 0.5, y0 + (float(y[j]) + 0.5) * f - 0.5)
            out[k] = BandFix(xy, float(mass[j]) * f * f / 255.0, float(band_refs[j]))  # w_x is 0–255
    return out
