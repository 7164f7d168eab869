"""The camera behind the lens for the newer presets: auto exposure, Bayer mosaic, glare.

Order, as in a camera: veiling glare, optical blur and vignetting → the AE
loop picks the exposure from the scene (what it meters is already clipped,
as a real sensor's statistics are) → the raw exposure, clipped at full scale
per colour site (so a highlight clips before white balance) → shot and read
noise per photosite, growing with the analogue gain the exposure needed →
RGGB mosaic at 10 bits and edge-aware demosaic → white-balance gains → gamma
→ 8 bits, BGR.
"""

from __future__ import annotations

import functools
import math
from typing import Optional

import cv2
import numpy as np

from . import isp, optics
from .scene import Scene

NOMINAL_EXPOSURE = 1.25  # the exposure at unity gain (what the original presets use)
RAW_LEVELS = 1023.0  # a 10-bit sensor
_LUMA = np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)


def _metering_weights(h: int, w: int) -> np.ndarray:
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    g = np.exp(-(((xx - (w - 1) / 2) / (0.45 * w)) ** 2 + ((yy - (h - 1) / 2) / (0.45 * h)) ** 2))
    return g / g.sum()


@functools.lru_cache(maxsize=8)
def _vignette(h: int, w: int, amount: float) -> np.ndarray:
    """Relative illumination: 1 at the centre, ``1 − amount`` in the corners (cos⁴-like)."""
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    r2 = ((xx - (w - 1) / 2) ** 2 + (yy - (h - 1) / 2) ** 2) / (((w - 1) / 2) ** 2 + ((h - 1) / 2) ** 2)
    falloff = 1.0 / (1.0 + r2 * (1.0 / np.sqrt(1.0 - amount) - 1.0)) ** 2
    falloff = falloff.astype(np.float32)
    falloff.setflags(write=False)
    return falloff


def auto_exposure(linear: np.ndarray, scene: Scene) -> float:
    """The exposure a settled AE loop picks: centre-weighted mean of the clipped
    luminance equal to ``ae_target``, times ``ae_error``, within ``ae_limits``."""
    im = scene.imaging
    small = cv2.resize(linear.astype(np.float32), (80, 60), interpolation=cv2.INTER_AREA)
    luma = (small * np.asarray(scene.lighting.wb_gains, np.float32)) @ _LUMA
    weights = _metering_weights(*luma.shape)
    lo, hi = math.log(1e-3), math.log(1e4)
    for _ in range(40):  # bisection on log exposure: metered brightness rises with exposure
        mid = 0.5 * (lo + hi)
        if float((np.minimum(luma * math.exp(mid), 1.0) * weights).sum()) < im.ae_target:
            lo = mid
        else:
            hi = mid
    e = math.exp(0.5 * (lo + hi)) * im.ae_error
    return float(min(max(e, im.ae_limits[0]), im.ae_limits[1]))


def _mosaic(raw: np.ndarray) -> np.ndarray:
    """RGGB: one colour per photosite."""
    out = np.empty(raw.shape[:2], dtype=raw.dtype)
    out[0::2, 0::2] = raw[0::2, 0::2, 0]
    out[0::2, 1::2] = raw[0::2, 1::2, 1]
    out[1::2, 0::2] = raw[1::2, 0::2, 1]
    out[1::2, 1::2] = raw[1::2, 1::2, 2]
    return out


def develop_sensor(linear: np.ndarray, scene: Scene, rng: Optional[np.random.Generator],
                   lut: np.ndarray, depth_m: Optional[np.ndarray] = None) -> np.ndarray:
    """Linear radiance to BGR uint8 through the camera described above (and, when
    ``scene.imaging.isp``, the lens of :mod:`.optics` and the ISP of :mod:`.isp`;
    defocus needs the per-pixel ``depth_m``)."""
    im, li = scene.imaging, scene.lighting
    img = linear.astype(np.float32)
    if im.focus_m > 0 and depth_m is not None:
        img = optics.defocus(img, depth_m, im.focus_m, im.aperture_m, scene.camera.fx_px)
    if im.glare > 0:
        h, w = img.shape[:2]
        small = cv2.resize(img, (max(w // 8, 1), max(h // 8, 1)), interpolation=cv2.INTER_AREA)
        small = cv2.GaussianBlur(small, (0, 0), 0.01 * w, borderType=cv2.BORDER_REFLECT)
        halo = cv2.resize(small, (w, h), interpolation=cv2.INTER_LINEAR)
        img = (1.0 - im.glare) * img + np.float32(im.glare) * halo
    if im.blur_sigma_px > 0.05:
        img = cv2.GaussianBlur(img, (0, 0), im.blur_sigma_px, borderType=cv2.BORDER_REFLECT)
    if im.isp:
        cam = scene.camera
        img = optics.barrel(optics.pan_blur(img, im.pan_blur_px), im.barrel_k1, cam.fx_px, cam.fy_px,
                            cam.cx_px, cam.cy_px)
        img = optics.lateral_colour(optics.soft_corners(img, im.soft_corners_px), im.lateral_colour)
    if im.vignetting > 0:
        img *= _vignette(*img.shape[:2], float(im.vignetting))[..., None]
    if im.ccm is not None:
        img = np.maximum(isp.to_sensor(img, im.ccm), 0.0)
    exposure = auto_exposure(img, scene) if im.auto_exposure else li.exposure
    gain = max(exposure / NOMINAL_EXPOSURE, 1.0)
    raw = np.minimum(img * np.float32(exposure), 1.0)  # photosites saturate
    if im.bayer:
        raw = _mosaic(raw)
    if rng is not None and (im.read_noise > 0 or im.shot_noise > 0):
        var = np.float32((im.read_noise * gain) ** 2) + np.float32(im.shot_noise * gain) * raw
        raw = raw + np.sqrt(var) * rng.standard_normal(raw.shape, dtype=np.float32)
    codes = np.clip(np.round(raw * RAW_LEVELS), 0, RAW_LEVELS).astype(np.uint16)
    if im.bayer:
        code = cv2.COLOR_BayerBG2RGB_EA if im.demosaic == "ea" else cv2.COLOR_BayerBG2RGB
        rgb = cv2.cvtColor(codes * np.uint16(64), code).astype(np.float32)
        rgb /= np.float32(RAW_LEVELS * 64)
    else:
        rgb = codes.astype(np.float32) / np.float32(RAW_LEVELS)
    if not im.isp:
        rgb *= np.asarray(li.wb_gains, dtype=np.float32)
        np.clip(rgb, 0.0, 1.0, out=rgb)
        idx = (rgb * 65535.0 + 0.5).astype(np.uint16)
        return cv2.cvtColor(np.take(lut, idx), cv2.COLOR_RGB2BGR)
    return _isp(rgb, scene, lut)


def _isp(rgb: np.ndarray, scene: Scene, lut: np.ndarray) -> np.ndarray:
    """Demosaiced raw (H, W, 3) float32 to BGR uint8: colour matrix, AWB, gamma,
    colour denoise, sharpening, chroma subsampling, JPEG (each only when the scene asks for it)."""
    im = scene.imaging
    if im.ccm is not None:
        rgb = isp.from_sensor(rgb, im.ccm)
    gains = isp.awb_gains(rgb, scene.lighting.wb_gains, im.awb_pull)
    rgb = rgb * np.asarray(gains, dtype=np.float32)
    np.clip(rgb, 0.0, 1.0, out=rgb)
    out = np.take(lut, (rgb * 65535.0 + 0.5).astype(np.uint16))
    out = isp.chroma_denoise(cv2.cvtColor(out, cv2.COLOR_RGB2BGR), im.chroma_denoise_px)
    out = cv2.cvtColor(isp.sharpen(cv2.cvtColor(out, cv2.COLOR_BGR2RGB), im.sharpen), cv2.COLOR_RGB2BGR)
    if im.h264_quality > 0:
        return isp.h264(out, im.h264_quality)
    if im.chroma_420 and im.jpeg_quality <= 0:
        out = isp.subsample_chroma(out)
    return isp.jpeg(out, im.jpeg_quality) if im.jpeg_quality > 0 else out
