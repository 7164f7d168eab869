"""Whether calibration data agree with the configured focal length, from the bearings.

With the camera's true ``fx_t, cx_t`` and the configured ``fx_c, cx_c``, a pixel
column ``u`` gives measured and true normalised offsets related by::

    tan θ_true = s · tan θ_meas + o,   s = fx_c / fx_t,   o = (cx_t − cx_c) / fx_t

(bearings + left, so tan θ = −x_n). Least squares over samples that span
enough bearings gives ``s`` and ``o``, hence the focal length and principal
point the bearings ask for. Range does not tell: a wrong focal length only
rescales the fitted band spacing, and the range fit stays good.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from .._compat import frozen
from .fit import Sample

MIN_SPREAD_RAD = math.radians(12.0)  # true bearings must span this much to fit the scale
WARN_ERR_DEG = 0.5  # mean bearing error above which the intrinsics are suspect
WARN_SCALE = 0.01  # |s − 1| above which the focal length is called wrong


@frozen
class FocalCheck:
    """What the bearings say about the intrinsics.

    ``fitted`` is False when the true bearings span less than
    :data:`MIN_SPREAD_RAD`; then ``fx_px``/``cx_px`` are the configured ones.
    """

    fitted: bool
    scale: float
    offset: float
    fx_px: float
    cx_px: float
    bearing_err_deg_mean: float  # as configured
    bearing_err_deg_mean_fitted: float  # after the scale and offset fit
    suspect: bool
    message: str


def check_focal(samples: Sequence[Sample], fx_px: float, cx_px: float) -> FocalCheck:
    """Fit the bearing scale and offset and judge the configured ``fx_px``, ``cx_px``.

    Parameters
    ----------
    samples : sequence of Sample
        Detected landmarks with their true bearing (rad, + left).
    fx_px, cx_px : float
        The configured intrinsics, in the pixels of the frames.

    Returns
    -------
    FocalCheck
        ``suspect`` when the mean bearing error exceeds :data:`WARN_ERR_DEG`
        and either the fit explains it (a focal length off by more than
        :data:`WARN_SCALE`, or an offset principal point) or there is too
        little bearing spread to tell; ``message`` says so in words.
    """
    tm = np.tan([s.bearing_meas_rad for s in samples])
    tt = np.tan([s.bearing_rad for s in samples])
    err0 = float(np.degrees(np.abs(np.arctan(tm) - np.arctan(tt))).mean()) if samples else math.nan
    spread = float(np.ptp(np.arctan(tt))) if samples else 0.0
    if len(samples) < 4 or spread < MIN_SPREAD_RAD:
        suspect = err0 > WARN_ERR_DEG
        msg = (f"bearings span {math.degrees(spread):.1f}° only (need {math.degrees(MIN_SPREAD_RAD):.0f}°): "
               "focal length not checked; place landmarks across the field of view")
        if suspect:
            msg = f"mean bearing error {err0:.2f}° with the configured intrinsics, and " + msg
        return FocalCheck(False, 1.0, 0.0, fx_px, cx_px, err0, err0, suspect, msg)
    a = np.column_stack([tm, np.ones_like(tm)])
    (s, o), *_ = np.linalg.lstsq(a, tt, rcond=None)
    err1 = float(np.degrees(np.abs(np.arctan(s * tm + o) - np.arctan(tt))).mean())
    fx_fit = fx_px / s
    cx_fit = cx_px + o * fx_fit
    wrong_f = abs(s - 1.0) > WARN_SCALE
    wrong_c = abs(cx_fit - cx_px) > 0.02 * fx_fit  # > ~1.1°
    suspect = err0 > WARN_ERR_DEG and (wrong_f or wrong_c) and err1 < 0.5 * err0
    if suspect:
        msg = (f"the intrinsics look wrong: mean bearing error {err0:.2f}° as configured, {err1:.2f}° with "
               f"fx_px {fx_fit:.1f} (configured {fx_px:.1f}) and cx_px {cx_fit:.1f} (configured {cx_px:.1f}); "
               "check camera.model or run 'rangebearing intrinsics', or pass --fit-focal")
    else:
        msg = (f"focal length agrees with the bearings: fx_px {fx_fit:.1f} fitted, {fx_px:.1f} configured; "
               f"mean bearing error {err0:.2f}°")
    return FocalCheck(True, float(s), float(o), float(fx_fit), float(cx_fit), err0, err1, suspect, msg)
