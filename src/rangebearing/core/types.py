"""Frozen value types shared by the pipeline stages, the model and the renderer.

Units are in the names: ``_m`` metres, ``_rad`` radians, ``_px`` pixels.
Image coordinates have x to the right and y down, origin at the top-left pixel
centre. Bearings are positive to the *left* of the optical axis (REP 103).
"""

from __future__ import annotations

import math
from typing import Optional, Tuple

import numpy as np

from .._compat import frozen
from ..errors import FrameError, FrameShapeError

XY = Tuple[float, float]
BBox = Tuple[int, int, int, int]  # x, y, width, height in pixels


@frozen
class CameraIntrinsics:
    """Pinhole intrinsics of the camera that took the frames.

    ``distortion`` holds OpenCV coefficients ``(k1, k2, p1, p2, k3)``; all zero
    means an ideal pinhole.
    """

    width_px: int = 640
    height_px: int = 480
    fx_px: float = 634.0
    fy_px: float = 634.0
    cx_px: float = 319.5
    cy_px: float = 239.5
    distortion: Tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0)

    @property
    def has_distortion(self) -> bool:
        return any(c != 0.0 for c in self.distortion)

    @property
    def hfov_rad(self) -> float:
        return 2.0 * math.atan(self.width_px / (2.0 * self.fx_px))

    def for_frame(self, width_px: int, height_px: int) -> CameraIntrinsics:
        """These intrinsics for frames of ``width_px × height_px``.

        The same size returns ``self``; another size of the same aspect ratio
        (within 1 %) is the same sensor area at another resolution
        (:meth:`scaled`). Raises FrameError for another aspect ratio (a cropped
        sensor mode), whose intrinsics cannot be derived from these.
        """
        if (width_px, height_px) == (self.width_px, self.height_px):
            return self
        if abs(width_px * self.height_px - height_px * self.width_px) > 0.01 * width_px * self.height_px:
            raise FrameShapeError(
                f"frame is {width_px}×{height_px} but the camera intrinsics are for {self.width_px}×{self.height_px}, "
                "another aspect ratio (a cropped sensor mode): configure camera.* for this resolution"
            )
        return self.scaled(width_px, height_px)

    def scaled(self, width_px: int, height_px: int) -> CameraIntrinsics:
        """The same camera at another resolution (same field of view)."""
        sx = width_px / self.width_px
        sy = height_px / self.height_px
        return CameraIntrinsics(
            width_px=width_px,
            height_px=height_px,
            fx_px=self.fx_px * sx,
            fy_px=self.fy_px * sy,
            cx_px=(self.cx_px + 0.5) * sx - 0.5,
            cy_px=(self.cy_px + 0.5) * sy - 0.5,
            distortion=self.distortion,
        )


@frozen
class LandmarkGeometry:
    """The passive landmark: a cylinder with a red band on top and a blue one below."""

    height_m: float = 0.070
    diameter_m: float = 0.035
    band_height_m: float = 0.015

    @property
    def radius_m(self) -> float:
        return self.diameter_m / 2.0

    @property
    def band_spacing_m(self) -> float:
        """Vertical distance between the red and blue band centres (55 mm by default)."""
        return self.height_m - self.band_height_m


MIN_FRAME_SIDE_PX = 8


def check_frame(frame: object, min_side_px: int = MIN_FRAME_SIDE_PX) -> np.ndarray:
    """Return ``frame`` if it is an H×W×3 uint8 array of at least ``min_side_px`` a side, else raise FrameError.

    The one frame check of the package: the pipeline calls it on every frame,
    and the sources call it (with ``min_side_px=1``) after converting what a
    decoder or camera produced.
    """
    if not isinstance(frame, np.ndarray):
        raise FrameError(f"frame is {type(frame).__name__}, not a numpy array")
    if frame.size == 0:
        raise FrameError(f"empty image of shape {frame.shape}")
    if frame.dtype != np.uint8:
        raise FrameError(f"frame has dtype {frame.dtype}, expected uint8")
    if frame.ndim != 3 or frame.shape[2] != 3:
        raise FrameError(f"frame has shape {frame.shape}, expected (height, width, 3) BGR")
    if frame.shape[0] < min_side_px or frame.shape[1] < min_side_px:
        raise FrameError(f"frame of {frame.shape[1]}×{frame.shape[0]} pixels is too small")
    return frame


def union(a: BBox, b: BBox) -> BBox:
    """The smallest box holding both boxes."""
    x0, y0 = min(a[0], b[0]), min(a[1], b[1])
    x1, y1 = max(a[0] + a[2], b[0] + b[2]), max(a[1] + a[3], b[1] + b[3])
    return (x0, y0, x1 - x0, y1 - y0)


@frozen
class Landmark:
    """One landmark seen in one frame: range, bearing and what they came from.

    ``d_v_m`` is the depth along the optical axis and ``d_h_m`` the lateral
    offset (positive left), as in the paper's figure 3; ``range_m`` is measured
    in the horizontal plane from the camera centre to the landmark's axis.
    The pipeline builds it positionally, once per reading: keep new fields at the end.
    """

    range_m: float
    bearing_rad: float
    d_v_m: float
    d_h_m: float
    l_px: float
    red_xy_px: XY
    blue_xy_px: XY
    width_px: float
    bbox_px: BBox
    in_envelope: bool
    # one-standard-deviation uncertainty of this measurement (pixel noise and band size through the model)
    range_sigma_m: float = 0.0
    bearing_sigma_rad: float = 0.0
    visible: float = 1.0  # fraction of the landmark seen (0-1); below 1 it is partly hidden or merged
    track_id: int = -1  # stable per neighbour while in view; -1 before tracking assigns one
    range_rate_mps: Optional[float] = None  # from the per-track constant-velocity filter, once it has history
    bearing_rate_radps: Optional[float] = None


@frozen
class FrameResult:
    """Everything the pipeline found in one frame. Nothing seen is an empty tuple."""

    landmarks: Tuple[Landmark, ...]
    tracked: bool = False  # measured in tracking windows rather than by a full-frame search
