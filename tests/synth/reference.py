"""An independent, slow reference for band centroids, and simple image moments.

The reference does not ray-cast: it walks the image columns finely, finds
where each column's ray meets the landmark cylinder (pinhole camera), and
integrates the band's vertical interval over the pixel rows it covers. It is
what a perfect box-filtering camera would record.
"""

from __future__ import annotations

from typing import Tuple

import numpy as np

from rangebearing.synth import BLUE_PAINT, RED_PAINT, LandmarkPose, Scene


def band_weights(linear: np.ndarray, colour: str) -> np.ndarray:
    """Per-pixel amount of red (R − G) or blue (B − G) paint in a linear render."""
    r, g, b = linear[..., 0], linear[..., 1], linear[..., 2]
    return np.clip(r - g, 0, None) if colour == "red" else np.clip(b - g, 0, None)


def centroid(weights: np.ndarray) -> Tuple[float, float]:
    """First moments over zeroth: (x, y) in pixels."""
    ys, xs = np.mgrid[0 : weights.shape[0], 0 : weights.shape[1]]
    m00 = weights.sum()
    return float((weights * xs).sum() / m00), float((weights * ys).sum() / m00)


def uint8_red_blue(bgr: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Red- and blue-dominant weights of an 8-bit BGR frame (simple, for coarse checks)."""
    img = bgr.astype(np.int32)
    b, g, r = img[..., 0], img[..., 1], img[..., 2]
    red = np.clip(r - np.maximum(g, b), 0, None).astype(float)
    blue = np.clip(b - np.maximum(g, r), 0, None).astype(float)
    red[red < 40] = 0
    blue[blue < 40] = 0
    return red, blue


def reference_centroid(scene: Scene, lm: LandmarkPose, colour: str,
                       steps: int = 60000) -> Tuple[float, float]:
    """Pixel-integrated centroid of one band, Lambert-weighted as the renderer shades."""
    cam, h, g = scene.camera, scene.camera_height_m, scene.geometry
    radius, base = g.radius_m, lm.base_height_m
    if colour == "red":
        y0, y1, paint = base + g.height_m - g.band_height_m, base + g.height_m, RED_PAINT
        k_paint = paint[0] - paint[1]
    else:
        y0, y1, paint = base, base + g.band_height_m, BLUE_PAINT
        k_paint = paint[2] - paint[1]
    light = np.asarray(scene.lighting.direction, float)
    light /= np.linalg.norm(light)
    amb = scene.lighting.ambient
    us = np.linspace(-0.5, cam.width_px - 0.5, steps * cam.width_px // 640 + 1)
    dx = (us - cam.cx_px) / cam.fx_px
    a, b = dx * dx + 1, dx * lm.x_m + lm.z_m
    c = lm.x_m**2 + lm.z_m**2 - radius**2
    disc = b * b - a * c
    ok = disc >= 0
    t = (b[ok] - np.sqrt(disc[ok])) / a[ok]
    u, dxo = us[ok], dx[ok]
    nx, nz = (dxo * t - lm.x_m) / radius, (t - lm.z_m) / radius
    shade = amb + (1 - amb) * np.maximum(nx * light[0] + nz * light[2], 0)
    v_top = cam.cy_px - cam.fy_px * (y1 - h) / t
    v_bot = cam.cy_px - cam.fy_px * (y0 - h) / t
    rows = np.arange(np.floor(v_top.min()) - 1, np.ceil(v_bot.max()) + 2)
    cover = np.clip(np.minimum(v_bot[:, None], rows + 0.5) - np.maximum(v_top[:, None], rows - 0.5),
                    0, None)
    cols = np.round(u)  # the pixel column each slice falls in
    w = (shade * k_paint)[:, None] * cover
    return float((w.sum(1) * cols).sum() / w.sum()), float((w * rows).sum() / w.sum())
