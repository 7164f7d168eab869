"""Everything the pure pipeline needs to know, and nothing else.

:class:`PipelineParams` bundles the camera intrinsics, the landmark geometry,
the detection settings and the range/bearing model. The application config
(:mod:`rangebearing.config`) holds one; :class:`~rangebearing.core.pipeline.Pipeline`
takes one. Nothing here knows about files, sources or the network.
"""

from __future__ import annotations

from typing import Tuple

from .._compat import frozen
from .identity import IdentityParams
from .types import CameraIntrinsics, LandmarkGeometry

METHODS = ("fast", "paper")
MODELS = ("pinhole", "paper")
WHITE_BALANCE = ("grey_world", "none")


@frozen
class DetectionParams:
    """How bands are found. ``method: paper`` is the paper's pipeline as published."""

    method: str = "fast"
    median_ksize: int = 15
    downscale: int = 2
    white_balance: str = "grey_world"
    red_hue: Tuple[Tuple[int, int], ...] = ((0, 10), (165, 179))
    blue_hue: Tuple[Tuple[int, int], ...] = ((98, 132),)
    s_min: int = 90
    v_min: int = 25
    min_band_px: float = 3.0
    # the most landmarks a frame can yield (detected, measured, tracked); the wire sends the nearest that
    # fit one datagram and counts the rest (net/fit.py), so this is not bounded by the packet size
    max_landmarks: int = 16
    tracking: bool = True
    full_scan_every: int = 8  # frames between periodic full scans, when full_scan_interval_s is 0
    # capture time between periodic full scans (a newcomer in mid-view shows within it, at any frame rate)
    full_scan_interval_s: float = 0.25


@frozen
class ModelParams:
    """Range and bearing from band centroids.

    ``pinhole``: range = f·spacing/(L·cos θ) + c, bearing = atan(x/f) after
    undistortion; in normalised image units, so it holds at any resolution.
    ``paper``: d_v = k/L, d_h = kh·px, θ = atan(d_h/d_v), d = d_v/cos θ, with
    k and kh in the pixels of the resolution they were fitted at.
    """

    kind: str = "pinhole"
    spacing_m: float = 0.055
    c_m: float = 0.0137
    k_px_m: float = 35.0
    kh_m_per_px: float = 0.00079
    cylinder_correction: bool = True
    envelope_range_m: Tuple[float, float] = (0.15, 2.0)
    envelope_bearing_rad: Tuple[float, float] = (-0.45, 0.45)
    # where landmarks stand in the image (calibrate fits them; see core/verify.py's height check):
    centre_below_m: float = 0.0  # a landmark's centre below the camera's optical centre, metres
    horizon_y_n: float = 0.0  # normalised image row of the horizon (tan of the camera's pitch, + down)
    centre_sigma_m: float = 0.0  # spread of the centre's height over the calibration landmarks; 0: not fitted


@frozen
class PipelineParams:
    """The camera, the landmark, how bands are found, how they become range and bearing, and track ids."""

    camera: CameraIntrinsics = CameraIntrinsics()
    landmark: LandmarkGeometry = LandmarkGeometry()
    detection: DetectionParams = DetectionParams()
    model: ModelParams = ModelParams()
    identity: IdentityParams = IdentityParams()
