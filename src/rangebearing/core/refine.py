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

from ..config import DetectionConfig
from .color import CHROMA_FLOOR, Gains, apply_gains, class_masks, ramp_table, to_hsv
from .types import XY, BandPair, BBox

# Bands taller than this (full-resolution pixels) are measured at 1/f resolution,
# so every band costs about the same whatever its range; a band still spans at
# least REFINE_BAND_PX / 2 rows, ample for sub-pixel moments.
REFINE_BAND_PX = 12
S_RAMP = 40  # saturation ramp half-width for the horizontal weights


def band_weights(hsv: np.ndarray, is_red: np.ndarray, cfg: DetectionConfig) -> Tuple[np.ndarray, np.ndarray]:
    """Weights ``(w_x, w_y)`` of a stack of band tiles, each (N, H, W) float32 in [0, 1].

    Parameters
    ----------
    hsv : (N, H, W, 3) uint8
        HSV tiles, one band each.
    is_red : (N,) bool
        Which tiles hold a red band (the others blue).

    Notes
    -----
    Both weights are zero outside the band's hue ranges and for pixels darker
    than 10.

    ``w_x`` weighs by saturation on a linear ramp from ``s_min − 40`` (0) to
    ``s_min + 40`` (1). Saturation does not depend on brightness, so shading
    across the cylinder does not pull the *horizontal* centroid.

    ``w_y`` weighs by chroma (max − min channel = S·V) relative to the band's
    own mean chroma, above a floor of 15 % of it. Chroma is linear in the share
    of a pixel the band covers whether the neighbour is the white body or the
    dark robot below, so the *vertical* centroid, and with it L, is unbiased;
    saturation would count a blue/black edge pixel as fully blue.
    """
    n, h, w = hsv.shape[:3]
    flat = hsv.reshape(n * h, w, 3)
    v_gate = min(cfg.v_min, 10)
    red, blue = class_masks(flat, cfg.red_hue, cfg.blue_hue, 1, v_gate)
    red, blue = red.reshape(n, h, w), blue.reshape(n, h, w)
    gate = np.where(is_red[:, None, None], red, blue) > 0
    s, v = hsv[..., 1], hsv[..., 2]
    w_x = cv2.LUT(s.reshape(n * h, w), ramp_table(max(0, cfg.s_min - S_RAMP), 2 * S_RAMP)).reshape(n, h, w)
    w_x *= gate
    chroma = s.astype(np.float32) * v
    core = gate & (s >= cfg.s_min)
    count = core.sum(axis=(1, 2))
    ref = np.where(count > 0, (chroma * core).sum(axis=(1, 2)) / np.maximum(count, 1), 0.0)
    floor = CHROMA_FLOOR * ref
    scale = np.where(ref > 0, 1.0 / np.maximum(ref - floor, 1e-6), 0.0).astype(np.float32)
    chroma -= floor[:, None, None].astype(np.float32)
    chroma *= scale[:, None, None]
    w_y = np.clip(chroma, 0.0, 1.0, out=chroma)
    w_y *= gate
    return w_x, w_y


def tile_centroids(w_x: np.ndarray, w_y: np.ndarray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-tile ``(x, y, ok)``: x from ``w_x``, y from ``w_y`` (first-order moments)."""
    _, h, w = w_x.shape
    m_x, m_y = w_x.sum(axis=(1, 2)), w_y.sum(axis=(1, 2))
    ok = (m_x > 1e-6) & (m_y > 1e-6)
    x = w_x.sum(axis=1) @ np.arange(w, dtype=np.float32) / np.where(ok, m_x, 1.0)
    y = w_y.sum(axis=2) @ np.arange(h, dtype=np.float32) / np.where(ok, m_y, 1.0)
    return x, y, ok


def _band_region(shape: Tuple[int, ...], bbox: BBox, margin: int) -> Tuple[int, int, int, int, int]:
    """``(x0, y0, x1, y1, f)``: the band's grown box, trimmed to a multiple of its scale ``f``."""
    h, w = shape[:2]
    bx, by, bw, bh = bbox
    f = max(1, bh // REFINE_BAND_PX)
    x0, y0 = max(0, bx - margin), max(0, by - margin)
    x1, y1 = min(w, bx + bw + margin), min(h, by + bh + margin)
    return x0, y0, x0 + (x1 - x0) // f * f, y0 + (y1 - y0) // f * f, f


def refine_pairs(
    bgr: np.ndarray, pairs: Sequence[BandPair], cfg: DetectionConfig, gains: Gains
) -> List[Optional[Tuple[XY, XY]]]:
    """Sub-pixel ``(red_xy, blue_xy)`` for each pair in full-resolution pixels; ``None`` if a band vanished.

    Each band is measured inside its blob's box grown by ``downscale + 1`` px,
    which covers the downscaling and the majority filter's erosion.
    """
    if not pairs:
        return []
    margin = cfg.downscale + 1
    regions = [_band_region(bgr.shape, b.bbox_px, margin) for p in pairs for b in (p.red, p.blue)]
    crops = []
    for x0, y0, x1, y1, f in regions:
        roi = bgr[y0:y1, x0:x1]
        if f > 1:
            roi = cv2.resize(roi, ((x1 - x0) // f, (y1 - y0) // f), interpolation=cv2.INTER_AREA)
        crops.append(roi)
    th = max(c.shape[0] for c in crops)
    tw = max(c.shape[1] for c in crops)
    stack = np.zeros((len(crops), th, tw, 3), np.uint8)
    for tile, crop in zip(stack, crops):
        tile[: crop.shape[0], : crop.shape[1]] = crop
    hsv = to_hsv(apply_gains(stack.reshape(-1, tw, 3), gains)).reshape(stack.shape)
    is_red = np.arange(len(crops)) % 2 == 0
    x, y, ok = tile_centroids(*band_weights(hsv, is_red, cfg))
    out: List[Optional[Tuple[XY, XY]]] = []
    for i in range(len(pairs)):
        if not (ok[2 * i] and ok[2 * i + 1]):
            out.append(None)
            continue
        pts = []
        for j in (2 * i, 2 * i + 1):
            x0, y0, _, _, f = regions[j]
            pts.append((x0 + (float(x[j]) + 0.5) * f - 0.5, y0 + (float(y[j]) + 0.5) * f - 0.5))
        out.append((pts[0], pts[1]))
    return out
