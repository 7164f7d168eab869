"""Stand-in for libcamera.ColorSpace: the three spaces picamera2 uses (utils.py:25) and their YCbCr maths."""

from __future__ import annotations

import numpy as np


class ColorSpace:
    """primaries / transferFunction / ycbcrEncoding / range as strings; str() as libcamera's toString()."""

    def __init__(self, name: str, primaries: str, transfer: str, encoding: str, range_: str) -> None:
        self.name = name
        self.primaries = primaries
        self.transferFunction = transfer
        self.ycbcrEncoding = encoding
        self.range = range_

    def __str__(self) -> str:
        return self.name

    __repr__ = __str__

    def __eq__(self, other: object) -> bool:  # picamera2/__init__.py: libcamera_colour_spaces_eq
        return isinstance(other, ColorSpace) and (
            (self.primaries, self.transferFunction, self.ycbcrEncoding, self.range)
            == (other.primaries, other.transferFunction, other.ycbcrEncoding, other.range))

    def __hash__(self) -> int:
        return hash((self.primaries, self.transferFunction, self.ycbcrEncoding, self.range))

    @staticmethod
    def Sycc() -> ColorSpace:
        return ColorSpace("sYCC", "Rec709", "Srgb", "Rec601", "Full")

    @staticmethod
    def Smpte170m() -> ColorSpace:
        return ColorSpace("SMPTE170M", "Smpte170m", "Rec709", "Rec601", "Limited")

    @staticmethod
    def Rec709() -> ColorSpace:
        return ColorSpace("Rec709", "Rec709", "Rec709", "Rec709", "Limited")


def rgb_to_yuv420(rgb: np.ndarray, space: ColorSpace | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Y (H, W), U and V (H/2, W/2) uint8 from RGB (H, W, 3) in `space` (None: sYCC, a webcam's default)."""
    kr, kb = (0.2126, 0.0722) if space is not None and space.ycbcrEncoding == "Rec709" else (0.299, 0.114)
    full = space is None or space.range == "Full"
    x = rgb.astype(np.float64) / 255.0
    y = kr * x[..., 0] + (1.0 - kr - kb) * x[..., 1] + kb * x[..., 2]
    cb = (x[..., 2] - y) / (2.0 * (1.0 - kb))
    cr = (x[..., 0] - y) / (2.0 * (1.0 - kr))
    h, w = y.shape
    cb = cb.reshape(h // 2, 2, w // 2, 2).mean(axis=(1, 3))  # the ISP's 4:2:0 chroma (cosited average)
    cr = cr.reshape(h // 2, 2, w // 2, 2).mean(axis=(1, 3))
    if full:
        planes = (y * 255.0, 128.0 + cb * 255.0, 128.0 + cr * 255.0)
    else:
        planes = (16.0 + y * 219.0, 128.0 + cb * 224.0, 128.0 + cr * 224.0)
    return tuple(np.clip(np.rint(p), 0, 255).astype(np.uint8) for p in planes)  # type: ignore[return-value]
