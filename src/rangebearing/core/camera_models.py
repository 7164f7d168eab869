"""Raspberry Pi camera presets: published sensor and lens figures → pinhole intrinsics.

The figures are the ones Raspberry Pi publishes in its camera hardware
specification (raspberrypi/documentation,
``documentation/asciidoc/accessories/camera/camera_hardware.adoc``, table
"Hardware Specification": sensor resolution, pixel size, focal length) and, for
the HQ camera, the focal length of the two lenses Raspberry Pi sells for it
(the 6 mm CS-mount and 16 mm C-mount lens guides linked from that page).

How a frame's pixels relate to the sensor
-----------------------------------------
libcamera reads a *sensor mode* (a window of the pixel array, possibly binned
2×2), then the ISP takes the ``ScalerCrop`` rectangle of it and scales that to
the output size. ``ScalerCrop`` and a mode's ``crop_limits`` are both given in
full-resolution pixel-array coordinates ``(x, y, width, height)``, so binning
does not matter here: only the rectangle of the pixel array that ends up in
the frame does. With pixel pitch ``p`` (mm), focal length ``f`` (mm) and the
crop ``(x0, y0, w, h)`` scaled to ``W × H`` output pixels::

    fx = (f / p) · W / w          fy = (f / p) · H / h
    cx = (cxa + 0.5 − x0) · W / w − 0.5     (cxa = (Na − 1)/2, the array's centre column)

When no crop is given, the crop is the largest rectangle with the output's
aspect ratio centred in the sensor mode's window (the whole array by default),
which is what libcamera's default ``ScalerCrop`` does.
"""

from __future__ import annotations

from typing import Dict, Optional, Tuple

from .._compat import frozen
from .types import CameraIntrinsics

Rect = Tuple[int, int, int, int]  # x, y, width, height in full-resolution pixel-array pixels


@frozen
class SensorPreset:
    """One camera module and lens, as published."""

    name: str
    sensor: str
    array_w_px: int  # full-resolution pixel array (the still resolution)
    array_h_px: int
    pixel_um: float  # pixel pitch, micrometres
    focal_mm: float
    hfov_deg_published: float = 0.0  # 0: depends on the lens / not published

    @property
    def focal_px(self) -> float:
        """Focal length in full-resolution pixels, ``f / p``."""
        return self.focal_mm / (self.pixel_um * 1e-3)


PRESETS: Dict[str, SensorPreset] = {
    p.name: p
    for p in (
        SensorPreset("pi-v1", "OV5647", 2592, 1944, 1.4, 3.60, 53.50),
        SensorPreset("pi-v2", "IMX219", 3280, 2464, 1.12, 3.04, 62.2),
        SensorPreset("pi-v3", "IMX708", 4608, 2592, 1.4, 4.74, 66.0),
        SensorPreset("pi-v3-wide", "IMX708", 4608, 2592, 1.4, 2.75, 102.0),
        SensorPreset("pi-hq-6mm", "IMX477", 4056, 3040, 1.55, 6.0),
        SensorPreset("pi-hq-16mm", "IMX477", 4056, 3040, 1.55, 16.0),
    )
}
MODELS = (*PRESETS, "custom")


def default_crop(preset: SensorPreset, width_px: int, height_px: int, mode_crop: Optional[Rect] = None) -> Rect:
    """The largest centred rectangle of ``mode_crop`` (default: the whole array) with the output's aspect ratio.

    Parameters
    ----------
    preset : SensorPreset
    width_px, height_px : int
        Output frame size.
    mode_crop : (x, y, w, h) of int, optional
        The sensor mode's window on the pixel array (Picamera2 ``sensor_modes[i]["crop_limits"]``,
        ``rpicam-hello --list-cameras`` "(x, y)/WxH crop").

    Returns
    -------
    (x, y, w, h) : tuple of int
        In full-resolution pixel-array pixels.
    """
    x0, y0, w0, h0 = mode_crop or (0, 0, preset.array_w_px, preset.array_h_px)
    if w0 * height_px > h0 * width_px:  # window wider than the output: crop the sides
        w, h = round(h0 * width_px / height_px), h0
    else:
        w, h = w0, round(w0 * height_px / width_px)
    return (x0 + (w0 - w) // 2, y0 + (h0 - h) // 2, w, h)


def preset_intrinsics(
    model: str,
    width_px: int,
    height_px: int,
    scaler_crop: Optional[Rect] = None,
    mode_crop: Optional[Rect] = None,
) -> CameraIntrinsics:
    """Pinhole intrinsics of a preset camera for an output size and crop.

    Parameters
    ----------
    model : str
        A key of :data:`PRESETS`.
    width_px, height_px : int
        Output frame size in pixels.
    scaler_crop : (x, y, w, h) of int, optional
        The rectangle of the pixel array that fills the frame (libcamera ``ScalerCrop``,
        full-resolution pixels). Default: :func:`default_crop` of ``mode_crop``.
    mode_crop : (x, y, w, h) of int, optional
        The sensor mode's window, used only when ``scaler_crop`` is not given.

    Returns
    -------
    CameraIntrinsics
        ``fx, fy, cx, cy`` in output pixels (pixel-centre convention: the
        first pixel's centre is 0), no distortion (none is published).

    Raises
    ------
    KeyError
        ``model`` is not a preset.
    ValueError
        The crop does not lie on the pixel array or is empty.
    """
    p = PRESETS[model]
    x0, y0, w, h = scaler_crop or default_crop(p, width_px, height_px, mode_crop)
    if w <= 0 or h <= 0 or x0 < 0 or y0 < 0 or x0 + w > p.array_w_px or y0 + h > p.array_h_px:
        raise ValueError(f"crop {(x0, y0, w, h)} is not inside the {p.array_w_px}×{p.array_h_px} pixel array")
    sx, sy = width_px / w, height_px / h
    cxa, cya = (p.array_w_px - 1) / 2.0, (p.array_h_px - 1) / 2.0
    return CameraIntrinsics(
        width_px=width_px,
        height_px=height_px,
        fx_px=p.focal_px * sx,
        fy_px=p.focal_px * sy,
        cx_px=(cxa + 0.5 - x0) * sx - 0.5,
        cy_px=(cya + 0.5 - y0) * sy - 0.5,
    )
