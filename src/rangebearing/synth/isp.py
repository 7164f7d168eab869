"""The image signal processor after the photosites: colour matrix, AWB, sharpening, chroma.

What the Raspberry Pi's ISP (libcamera's ``rpi`` pipeline) does to a raw frame,
as far as it changes what a detector sees:

- **Colour matrix.** A sensor's colour filters overlap, so its raw RGB is a
  desaturated mix of the scene's (``raw = S · rgb``); the ISP undoes it with a
  colour-correction matrix ``CCM = S⁻¹`` whose rows sum to 1 (grey stays
  grey). Noise, added in raw space, comes out amplified and correlated between
  channels (chroma noise), and a saturated band clips in raw space first.
  :data:`OV5647_CCMS` are the Pi Camera v1's matrices at about 3000, 4700 and
  5900 K (libcamera's ``ov5647.json`` tuning).
- **Auto white balance.** The AWB estimates the light from the frame's own
  statistics, so a large coloured area (a navy carpet, a red wall) pulls it:
  :func:`awb_gains` mixes the intended gains with grey-world gains of the
  unclipped, not-too-dark pixels.
- **Colour denoise.** Chroma smoothed over a few pixels (:func:`chroma_denoise`),
  which takes most of the chroma noise and softens colour edges.
- **Sharpening.** Luma-only unsharp masking above a small threshold, limited:
  light and dark halos along band edges (:func:`sharpen`).
- **Chroma.** YUV 4:2:0 output (the ``lores`` stream, H.264, JPEG) keeps
  colour at half resolution (:func:`subsample_chroma`); :func:`jpeg` passes a
  frame through the camera's JPEG encoder.
"""

from __future__ import annotations

import functools
from typing import Tuple

import cv2
import numpy as np

OV5647_CCMS = (
    ((1.88195, -0.26249, -0.61946), (-0.63842, 2.11535, -0.47693), (-0.13531, -0.99739, 2.13271)),
    ((2.00971, -0.51461, -0.49511), (-0.52109, 2.01003, -0.48894), (-0.09527, -0.67318, 1.76845)),
    ((2.13616, -0.65283, -0.48333), (-0.48364, 1.93115, -0.44751), (-0.13465, -0.54831, 1.68295)),
)
_LUMA = np.array([0.299, 0.587, 0.114], dtype=np.float32)  # BT.601, as the ISP's YCbCr


@functools.lru_cache(maxsize=8)
def _matrices(ccm: Tuple[float, ...]) -> Tuple[np.ndarray, np.ndarray]:
    m = np.asarray(ccm, dtype=np.float64).reshape(3, 3)
    m = m / m.sum(axis=1, keepdims=True)  # grey stays grey
    s = np.linalg.inv(m)
    out = (m.astype(np.float32), s.astype(np.float32))
    for a in out:
        a.setflags(write=False)
    return out


def to_sensor(rgb: np.ndarray, ccm: Tuple[float, ...]) -> np.ndarray:
    """Scene linear RGB (H, W, 3) to the sensor's raw response ``S · rgb`` (``S = CCM⁻¹``)."""
    return rgb @ _matrices(ccm)[1].T


def from_sensor(raw: np.ndarray, ccm: Tuple[float, ...]) -> np.ndarray:
    """The ISP's colour correction: ``CCM · raw``."""
    return raw @ _matrices(ccm)[0].T


def awb_gains(rgb: np.ndarray, intended: Tuple[float, float, float], pull: float
              ) -> Tuple[float, float, float]:
    """Gains an AWB pulled by the frame's colours picks: ``intended^(1−pull) · grey^pull``.

    ``grey`` are the grey-world gains (green = 1) of the pixels neither clipped
    nor dark; each gain is kept within 0.4–3.
    """
    if pull <= 0.0:
        return intended
    small = cv2.resize(rgb, (max(rgb.shape[1] // 8, 1), max(rgb.shape[0] // 8, 1)),
                       interpolation=cv2.INTER_AREA).reshape(-1, 3)
    ok = (small.max(axis=1) < 0.95) & (small @ _LUMA > 0.02)
    if ok.sum() < 20:
        return intended
    mean = small[ok].mean(axis=0).astype(np.float64) * np.asarray(intended)
    grey = mean[1] / np.maximum(mean, 1e-6)
    g = np.asarray(intended) * grey**pull
    g = np.clip(g / g[1], 0.4, 3.0)
    return float(g[0]), 1.0, float(g[2])


def sharpen(rgb8: np.ndarray, strength: float, sigma_px: float = 1.0, threshold: float = 2.0,
            limit: float = 40.0) -> np.ndarray:
    """Luma unsharp mask on an 8-bit RGB image: detail above ``threshold`` levels,
    times ``strength``, at most ``limit`` levels, added to every channel."""
    if strength <= 0.0:
        return rgb8
    img = rgb8.astype(np.float32)
    y = img @ _LUMA
    detail = y - cv2.GaussianBlur(y, (0, 0), sigma_px, borderType=cv2.BORDER_REFLECT)
    d = np.sign(detail) * np.maximum(np.abs(detail) - threshold, 0.0) * strength
    d = np.clip(d, -limit, limit)
    return np.clip(np.round(img + d[..., None]), 0, 255).astype(np.uint8)


def chroma_denoise(bgr8: np.ndarray, sigma_px: float) -> np.ndarray:
    """The ISP's colour denoise: chroma (not luma) smoothed with a Gaussian of ``sigma_px``."""
    if sigma_px <= 0.05:
        return bgr8
    ycc = cv2.cvtColor(bgr8, cv2.COLOR_BGR2YCrCb)
    for ch in (1, 2):
        ycc[..., ch] = cv2.GaussianBlur(ycc[..., ch], (0, 0), sigma_px, borderType=cv2.BORDER_REFLECT)
    return cv2.cvtColor(ycc, cv2.COLOR_YCrCb2BGR)


def subsample_chroma(bgr8: np.ndarray, blocks: bool = False) -> np.ndarray:
    """YCbCr 4:2:0 and back: chroma averaged over 2×2 pixels, then interpolated
    (``blocks``: repeated, as a decoder without chroma interpolation shows it)."""
    ycc = cv2.cvtColor(bgr8, cv2.COLOR_BGR2YCrCb)
    h, w = ycc.shape[:2]
    up = cv2.INTER_NEAREST if blocks else cv2.INTER_LINEAR
    for ch in (1, 2):
        small = cv2.resize(ycc[..., ch], ((w + 1) // 2, (h + 1) // 2), interpolation=cv2.INTER_AREA)
        ycc[..., ch] = cv2.resize(small, (w, h), interpolation=up)
    return cv2.cvtColor(ycc, cv2.COLOR_YCrCb2BGR)


def h264(bgr8: np.ndarray, quality: int) -> np.ndarray:
    """A video encoder's frame, roughly: colour in 2×2 blocks (4:2:0, not interpolated), then
    8×8 block transform coding at ``quality`` (JPEG's quantiser: blocking and ringing)."""
    return jpeg(subsample_chroma(bgr8, blocks=True), quality)


@functools.lru_cache(maxsize=4)
def tone_lut(tone: str) -> np.ndarray:
    """uint8 table over 16-bit linear codes (0–65535) for a tone curve other than a plain gamma.

    ``"srgb"``: IEC 61966-2-1's piecewise curve (linear toe below 0.0031308).
    ``"filmic"``: sRGB followed by an S-shaped contrast curve ``y + 4c·y(1−y)(y−½)``
    with c = 0.35 (darker shadows, brighter highlights, mid-grey kept; slope 1 − 2c at
    black and white), as a camera's "contrast" or filmic look does.
    """
    x = np.arange(65536, dtype=np.float64) / 65535.0
    y = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)
    if tone == "filmic":
        y = y + 4.0 * 0.35 * y * (1.0 - y) * (y - 0.5)
    elif tone != "srgb":
        raise ValueError(f"unknown tone curve {tone!r}")
    out = np.round(255.0 * np.clip(y, 0.0, 1.0)).astype(np.uint8)
    out.setflags(write=False)
    return out


def jpeg(bgr8: np.ndarray, quality: int) -> np.ndarray:
    """The frame through a JPEG encoder (4:2:0) and decoder at ``quality``."""
    ok, buf = cv2.imencode(".jpg", bgr8, [int(cv2.IMWRITE_JPEG_QUALITY), int(quality)])
    if not ok:
        raise OSError("OpenCV could not encode a JPEG image")
    return cv2.imdecode(buf, cv2.IMREAD_COLOR)
