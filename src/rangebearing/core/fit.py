"""Fitting the range model to frames with known range and bearing.

Pure least squares on measured band geometry; the CLI does the I/O.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Sequence, Tuple

import numpy as np

from .._compat import frozen
from ..errors import CalibrationError
from .params import ModelParams

MIN_SAMPLES = 4
MIN_RANGE_SPREAD = 1.15  # farthest / nearest true range
# the landmarks' height in the image is fitted only when it is one height: robots alike on one floor
MAX_CENTRE_SIGMA_M = 0.012


@frozen
class Sample:
    """One detected landmark with its true position."""

    frame: str
    l_px: float  # band centroid distance in the frame's pixels (the paper's L)
    l_norm: float  # the same in normalised image units (L / f, after undistortion)
    bearing_meas_rad: float
    px_left: float  # horizontal offset of the centroids from the principal point, + left
    range_m: float
    bearing_rad: float
    y_norm: float = math.nan  # normalised image row of the band centroids' midpoint (+ down)


@frozen
class Residual:
    frame: str
    range_m: float
    fitted_range_m: float
    bearing_rad: float
    fitted_bearing_rad: float

    @property
    def range_err_pct(self) -> float:
        return 100.0 * (self.fitted_range_m - self.range_m) / self.range_m

    @property
    def bearing_err_deg(self) -> float:
        return math.degrees(self.fitted_bearing_rad - self.bearing_rad)


@frozen
class Fit:
    """A fitted model, its residuals, and summary errors."""

    model: ModelParams
    residuals: Tuple[Residual, ...]
    range_err_pct_mean: float
    range_err_pct_max: float
    bearing_err_deg_mean: float


def check_samples(samples: Sequence[Sample]) -> None:
    """Refuse data that cannot support a fit, saying why."""
    if not samples:
        raise CalibrationError("no landmark was detected in any calibration frame")
    if len(samples) < MIN_SAMPLES:
        raise CalibrationError(f"only {len(samples)} detected landmark(s); at least {MIN_SAMPLES} are needed")
    ranges = [s.range_m for s in samples]
    if max(ranges) / min(ranges) < MIN_RANGE_SPREAD:
        raise CalibrationError(
            f"all true ranges lie within {min(ranges):.3f}–{max(ranges):.3f} m: one distance only; "
            f"take frames over a spread of distances (farthest ≥ {MIN_RANGE_SPREAD}× nearest)"
        )


def _envelope(samples: Sequence[Sample]) -> Tuple[Tuple[float, float], Tuple[float, float]]:
    r = [s.range_m for s in samples]
    b = [s.bearing_rad for s in samples]
    return (round(min(r), 4), round(max(r), 4)), (round(min(b), 4), round(max(b), 4))


def fit_model(samples: Sequence[Sample], base: ModelParams) -> Fit:
    """Fit ``base.kind``'s coefficients and the validity envelope.

    pinhole: ``range = S/(L_n·cos θ) + c`` by linear least squares in (S, c).
    paper:   ``d_v = k/L`` and ``d_h = k_h·px`` by least squares through the origin.
    """
    check_samples(samples)
    L = np.array([s.l_px for s in samples])
    th_m = np.array([s.bearing_meas_rad for s in samples])
    rng = np.array([s.range_m for s in samples])
    th = np.array([s.bearing_rad for s in samples])
    env_r, env_b = _envelope(samples)
    if base.kind == "paper":
        d_v, d_h = rng * np.cos(th), rng * np.sin(th)
        k = float(np.sum(d_v / L) / np.sum(1.0 / L**2))
        px = np.array([s.px_left for s in samples])
        kh = float(np.sum(d_h * px) / np.sum(px**2)) if np.sum(px**2) > 0 else base.kh_m_per_px
        if kh <= 0:
            raise CalibrationError("fitted k_h is not positive: check the sign of the true bearings (+ is left)")
        model = dataclasses.replace(base, k_px_m=k, kh_m_per_px=kh, envelope_range_m=env_r, envelope_bearing_rad=env_b)
        fv, fh = k / L, kh * px
        f_th = np.arctan2(fh, fv)
        f_rng = fv / np.cos(f_th)
    else:
        x = 1.0 / (np.array([s.l_norm for s in samples]) * np.cos(th_m))
        a = np.column_stack((x, np.ones_like(x)))
        (spacing, c), *_ = np.linalg.lstsq(a, rng, rcond=None)
        if spacing <= 0:
            raise CalibrationError(
                "fitted spacing is not positive: the band spacing in the image does not shrink with range"
            )
        model = dataclasses.replace(
            base, spacing_m=float(spacing), c_m=float(c), envelope_range_m=env_r, envelope_bearing_rad=env_b
        )
        f_rng = spacing * x + c
        f_th = th_m
    model = dataclasses.replace(model, **centre_height(samples, model.spacing_m))
    residuals = tuple(
        Residual(s.frame, s.range_m, float(fr), s.bearing_rad, float(fb)) for s, fr, fb in zip(samples, f_rng, f_th)
    )
    r_err = np.abs([r.range_err_pct for r in residuals])
    b_err = np.abs([r.bearing_err_deg for r in residuals])
    return Fit(model, residuals, float(r_err.mean()), float(r_err.max()), float(b_err.mean()))


def centre_height(samples: Sequence[Sample], spacing_m: float) -> dict:
    """``centre_below_m``, ``horizon_y_n`` and ``centre_sigma_m`` of the landmarks in the samples.

    A landmark centre ``Y`` below the camera, at depth ``Z``, images at the normalised row
    ``y_n = Y/Z + t`` (``t``: tan of the camera's pitch, the horizon's row); with
    ``Z = spacing/L_n`` that is ``y_n = t + (Y/spacing)·L_n``, a line in ``L_n``. Fitted by
    least squares, once more without the samples beyond 3 σ (a mismatched detection). When
    there are too few samples, or the heights spread more than :data:`MAX_CENTRE_SIGMA_M`
    (landmarks at different heights), ``centre_sigma_m`` is 0: no height is known.
    """
    keep = [s for s in samples if s.y_norm == s.y_norm]
    off = {"centre_below_m": 0.0, "horizon_y_n": 0.0, "centre_sigma_m": 0.0}
    if len(keep) < 2 * MIN_SAMPLES:
        return off
    ln = np.array([s.l_norm for s in keep])
    yn = np.array([s.y_norm for s in keep])
    use = np.ones(len(ln), bool)
    for _ in range(2):
        if use.sum() < 2 * MIN_SAMPLES or np.ptp(ln[use]) <= 0:
            return off
        a = np.column_stack((np.ones(int(use.sum())), ln[use]))
        (t, k), *_ = np.linalg.lstsq(a, yn[use], rcond=None)
        dev_m = (yn - t - k * ln) * spacing_m / ln  # each landmark's height off the fit, metres
        sigma = float(np.sqrt(np.mean(dev_m[use] ** 2)))
        use = np.abs(dev_m) <= max(3.0 * sigma, 1e-4)
    if not sigma <= MAX_CENTRE_SIGMA_M:
        return off
    return {"centre_below_m": float(k * spacing_m), "horizon_y_n": float(t), "centre_sigma_m": max(sigma, 1e-4)}
