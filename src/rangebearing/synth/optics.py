"""The lens in front of the sensor: defocus by depth, softer corners, lateral colour.

The Pi Camera v1 (OV5647) has a fixed-focus f/2.9, 3.6 mm lens focused far
away, so a landmark 0.15–0.3 m from it is visibly soft. A thin lens focused at
``z_f`` blurs a point at depth ``z`` into a disc of diameter
``c = A · f · |1/z − 1/z_f|`` on the sensor (``A`` the aperture diameter,
1.24 mm at f/2.9), which is ``A · fx_px · |1/z − 1/z_f|`` pixels: about 3 px
at 0.2 m for a 640-pixel-wide frame focused at 1 m.

:func:`defocus` blurs the linear radiance with that disc, depth by depth:
pixels are grouped into depth layers by blur level, each pixel's light is
split between its level's disc and the next one (linear weights, so the blur
grows smoothly along a floor), and layers are composited back to front (``out = c + (1 − α)·out``), so
a near, blurred landmark spreads over what lies behind it and a far one does
not bleed over a nearer edge. Where a nearer layer's blurred edge lets the
background through, what was hidden behind it is filled in from its
surroundings (a normalised blur), as a lens sees round a near edge. Discs are symmetric: a wholly visible band's
centroid stays where it was.

:func:`soft_corners` widens the optical blur towards the image corners (a
cheap lens's field curvature), :func:`lateral_colour` scales the red and blue
images about the centre by ``±amount`` (lateral chromatic aberration: colour
fringes that grow towards the edges).
"""

from __future__ import annotations

import functools
import math
from typing import Optional, Sequence, Tuple

import cv2
import numpy as np

LEVELS_PX = (0.0, 1.0, 1.5, 2.0, 2.75, 3.5, 4.5, 6.0, 8.0, 11.0)  # disc diameters


@functools.lru_cache(maxsize=16)
def disc(diameter_px: float) -> np.ndarray:
    """A normalised, anti-aliased disc kernel of the given diameter (odd size)."""
    r = diameter_px / 2.0
    n = int(np.ceil(r + 0.5))
    yy, xx = np.mgrid[-n:n + 1, -n:n + 1].astype(np.float64)
    sub = (np.arange(4) + 0.5) / 4 - 0.5  # 4x4 coverage per kernel cell
    acc = np.zeros_like(xx)
    for a in sub:
        for b in sub:
            acc += (xx + a) ** 2 + (yy + b) ** 2 <= r * r
    k = (acc / acc.sum()).astype(np.float32)
    k.setflags(write=False)
    return k


def coc_px(depth_m: np.ndarray, focus_m: float, aperture_m: float, fx_px: float) -> np.ndarray:
    """Blur-disc diameter (px) of points at ``depth_m`` (Z along the optical axis)."""
    with np.errstate(divide="ignore"):
        inv = np.where(np.isfinite(depth_m) & (depth_m > 0), 1.0 / depth_m, 0.0)
    return aperture_m * fx_px * np.abs(inv - 1.0 / focus_m)


def _split(c: np.ndarray, levels: Sequence[float]) -> Tuple[np.ndarray, np.ndarray]:
    """Index of the level below each diameter and the weight of the one above."""
    lv = np.asarray(levels)
    c = np.clip(c, lv[0], lv[-1])
    i = np.clip(np.searchsorted(lv, c, side="right") - 1, 0, len(lv) - 2)
    w = (c - lv[i]) / (lv[i + 1] - lv[i])
    return i, w


def defocus(linear: np.ndarray, depth_m: np.ndarray, focus_m: float, aperture_m: float,
            fx_px: float) -> np.ndarray:
    """Thin-lens defocus of (H, W, 3) linear radiance; ``depth_m`` (H, W) per pixel.

    Points beyond the focus distance blur too (by ``A·fx/z_f`` at most); they
    are composited as if nearer ones hid them, which only matters for a frame
    focused in the middle of the scene.
    """
    c = coc_px(depth_m, focus_m, aperture_m, fx_px).astype(np.float32)
    near = np.isfinite(depth_m) & (depth_m < focus_m)
    # back to front: farther than focus first (blur rising with distance), then nearer (rising as they come closer)
    far_c, near_c = np.where(near, 0.0, c), np.where(near, c, 0.0)
    img = linear.astype(np.float32)
    out = np.zeros_like(img)  # premultiplied by its coverage ``cover``
    cover = np.zeros(img.shape[:2], np.float32)
    for sign, cc, mask in ((1, far_c, ~near), (-1, near_c, near)):
        i, w = _split(cc, LEVELS_PX)
        used = np.unique(i[mask]).tolist()
        for lv in (used if sign < 0 else used[::-1]):  # far side: the biggest blur is farthest
            layer = mask & (i == lv)
            crop = _crop(layer, LEVELS_PX[lv + 1])
            if crop is None:
                continue
            share = layer[crop].astype(np.float32)
            hi = share * w[crop].astype(np.float32)
            sub = img[crop]
            alpha, col = np.zeros_like(share), np.zeros_like(sub)
            for part, size in ((share - hi, LEVELS_PX[lv]), (hi, LEVELS_PX[lv + 1])):
                if not part.any():
                    continue
                if size < 0.5:
                    alpha += part
                    col += sub * part[..., None]
                else:
                    k = disc(size)
                    alpha += cv2.filter2D(part, -1, k, borderType=cv2.BORDER_REFLECT)
                    col += cv2.filter2D(sub * part[..., None], -1, k, borderType=cv2.BORDER_REFLECT)
            np.clip(alpha, 0.0, 1.0, out=alpha)
            if cover.any():
                _fill(out, cover, crop, LEVELS_PX[lv + 1])
            out[crop] = col + (1.0 - alpha)[..., None] * out[crop]
            cover[crop] = alpha + (1.0 - alpha) * cover[crop]
    return out / np.maximum(cover, 1e-6)[..., None]


def _crop(layer: np.ndarray, size_px: float) -> Optional[Tuple[slice, slice]]:
    """The layer's bounding box, grown by its blur (None for an empty layer)."""
    rows, cols = np.flatnonzero(layer.any(axis=1)), np.flatnonzero(layer.any(axis=0))
    if rows.size == 0:
        return None
    pad = math.ceil(size_px / 2) + 1
    h, w = layer.shape
    return (slice(max(rows[0] - pad, 0), min(rows[-1] + pad + 1, h)),
            slice(max(cols[0] - pad, 0), min(cols[-1] + pad + 1, w)))


def _fill(out: np.ndarray, cover: np.ndarray, crop: Tuple[slice, slice], size_px: float) -> None:
    """Complete what lies behind the layers so far inside ``crop``, in place: where they
    do not cover a pixel (a nearer object stood there), the surroundings' colour
    (a normalised blur)."""
    if cover[crop].min() > 0.999:
        return
    sigma = max(size_px, 2.0)
    pad = int(3 * sigma) + 1
    h, w = cover.shape
    r0, r1 = max(crop[0].start - pad, 0), min(crop[0].stop + pad, h)
    c0, c1 = max(crop[1].start - pad, 0), min(crop[1].stop + pad, w)
    num = cv2.GaussianBlur(out[r0:r1, c0:c1], (0, 0), sigma, borderType=cv2.BORDER_REFLECT)
    den = cv2.GaussianBlur(cover[r0:r1, c0:c1], (0, 0), sigma, borderType=cv2.BORDER_REFLECT)
    inner = (slice(crop[0].start - r0, crop[0].stop - r0), slice(crop[1].start - c0, crop[1].stop - c0))
    num, den = num[inner], den[inner]
    known = den > 1e-4
    fill = np.where(known[..., None], num / np.maximum(den, 1e-4)[..., None], 0.0)
    gap = (1.0 - cover[crop]) * known
    out[crop] += gap[..., None] * fill
    cover[crop] += gap


def soft_corners(img: np.ndarray, extra_sigma_px: float) -> np.ndarray:
    """Blur growing with the squared distance from the centre, ``extra_sigma_px`` in the corners."""
    if extra_sigma_px <= 0.05:
        return img
    h, w = img.shape[:2]
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    r2 = ((xx - (w - 1) / 2) ** 2 + (yy - (h - 1) / 2) ** 2) / (((w - 1) / 2) ** 2 + ((h - 1) / 2) ** 2)
    blurred = cv2.GaussianBlur(img, (0, 0), extra_sigma_px, borderType=cv2.BORDER_REFLECT)
    k = np.minimum(r2, 1.0)[..., None]
    return (1.0 - k) * img + k * blurred


def lateral_colour(img: np.ndarray, amount: float) -> np.ndarray:
    """Red scaled by ``1 + amount`` and blue by ``1 − amount`` about the image centre."""
    if amount == 0.0:
        return img
    h, w = img.shape[:2]
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    cx, cy = (w - 1) / 2, (h - 1) / 2
    out = img.copy()
    for ch, s in ((0, 1.0 + amount), (2, 1.0 - amount)):
        mx = (cx + (xx - cx) / s).astype(np.float32)
        my = (cy + (yy - cy) / s).astype(np.float32)
        out[..., ch] = cv2.remap(img[..., ch], mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)
    return out


def box_kernel(length_px: float) -> np.ndarray:
    """A centred 1-D box ``length_px`` long (fractional ends weighted by their overlap), summing to 1."""
    half = length_px / 2.0
    n = 2 * math.ceil(half + 0.5) + 1
    x = np.arange(n, dtype=np.float64) - n // 2
    k = np.clip(np.minimum(x + 0.5, half) - np.maximum(x - 0.5, -half), 0.0, None)
    return (k / k.sum()).astype(np.float32)


def pan_blur(img: np.ndarray, length_px: float) -> np.ndarray:
    """The whole frame smeared horizontally over ``length_px`` (the camera turning at a constant
    rate during the exposure; symmetric about the exposure's middle, so nothing moves)."""
    if length_px <= 0.5:
        return img
    k = box_kernel(length_px).reshape(1, -1)
    return cv2.filter2D(img, -1, k, borderType=cv2.BORDER_REFLECT)


def barrel(img: np.ndarray, k1: float, fx_px: float, fy_px: float, cx_px: float, cy_px: float) -> np.ndarray:
    """The image seen through a lens with radial distortion ``1 + k1·r²`` (r in normalised
    coordinates about the principal point; k1 < 0 is barrel): a point the pinhole puts at
    ``x`` appears at ``x·(1 + k1·r²)``."""
    if k1 == 0.0:
        return img
    h, w = img.shape[:2]
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    xn, yn = (xx - cx_px) / fx_px, (yy - cy_px) / fy_px
    # the undistorted point behind each output pixel (fixed-point steps converge fast for |k1·r²| << 1)
    xu, yu = xn.copy(), yn.copy()
    for _ in range(3):
        s = 1.0 + k1 * (xu * xu + yu * yu)
        xu, yu = xn / s, yn / s
    mx = (cx_px + xu * fx_px).astype(np.float32)
    my = (cy_px + yu * fy_px).astype(np.float32)
    return cv2.remap(img, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)
