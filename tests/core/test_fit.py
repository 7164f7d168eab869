import dataclasses
import math

import numpy as np
import pytest

from rangebearing.core.fit import Sample, fit_model
from rangebearing.core.params import ModelParams
from rangebearing.errors import CalibrationError

S, C, F = 0.0552, 0.0125, 634.0


def pinhole_samples(ranges, bearings):
    """Samples that follow range = S/(L_n cos θ) + C exactly."""
    out = []
    for i, (r, b) in enumerate(zip(ranges, bearings)):
        l_norm = S / ((r - C) * math.cos(b))
        out.append(Sample(str(i), l_norm * F, l_norm, b, 0.0, r, b))
    return out


def test_pinhole_fit_recovers_spacing_and_c_and_the_envelope():
    s = pinhole_samples([0.2, 0.4, 0.7, 1.1, 1.6], [0.1, -0.3, 0.0, 0.35, -0.2])
    fit = fit_model(s, ModelParams())
    assert fit.model.spacing_m == pytest.approx(S, rel=1e-9)
    assert fit.model.c_m == pytest.approx(C, abs=1e-9)
    assert fit.range_err_pct_max < 1e-6
    assert fit.model.envelope_range_m == (0.2, 1.6)
    assert fit.model.envelope_bearing_rad == (-0.3, 0.35)


def test_paper_fit_recovers_k_and_kh():
    k, kh = 36.0, 0.0008
    samples = []
    for i, (L, px) in enumerate([(60, 40), (100, -80), (80, 10), (120, 150)]):
        d_v, d_h = k / L, kh * px
        r, b = math.hypot(d_v, d_h), math.atan2(d_h, d_v)
        samples.append(Sample(str(i), L, L / F, b, px, r, b))
    fit = fit_model(samples, dataclasses.replace(ModelParams(), kind="paper"))
    assert fit.model.k_px_m == pytest.approx(k)
    assert fit.model.kh_m_per_px == pytest.approx(kh)


@pytest.mark.parametrize(
    "samples, message",
    [
        ([], "no landmark was detected"),
        (pinhole_samples([0.3, 0.5], [0.0, 0.0]), "at least 4"),
        (pinhole_samples([0.5, 0.5, 0.51, 0.5, 0.52], [0.0, 0.1, -0.1, 0.2, 0.0]), "one distance only"),
    ],
)
def test_fit_refuses_data_that_cannot_support_it(samples, message):
    with pytest.raises(CalibrationError, match=message):
        fit_model(samples, ModelParams())


def height_samples(centre_below_m, horizon_y_n, jitter_m=0.0, n=12):
    """Pinhole samples whose band midpoints image a landmark centre ``centre_below_m`` under the camera."""
    rng = np.random.default_rng(5)
    out = []
    for s in pinhole_samples(np.linspace(0.2, 1.4, n), np.zeros(n)):
        depth = S / s.l_norm
        y = horizon_y_n + (centre_below_m + jitter_m * rng.standard_normal()) / depth
        out.append(dataclasses.replace(s, y_norm=y))
    return out


def test_calibration_fits_where_landmarks_stand_in_the_image():
    fit = fit_model(height_samples(0.012, -0.035), ModelParams())  # 12 mm below the camera, pitched up 2 deg
    assert fit.model.centre_below_m == pytest.approx(0.012, abs=1e-6)
    assert fit.model.horizon_y_n == pytest.approx(-0.035, abs=1e-6)
    assert 0 < fit.model.centre_sigma_m < 1e-3


def test_no_height_is_fitted_from_landmarks_at_different_heights_or_without_rows():
    assert fit_model(height_samples(0.0, 0.0, jitter_m=0.03), ModelParams()).model.centre_sigma_m == 0.0
    assert fit_model(pinhole_samples([0.2, 0.4, 0.7, 1.1, 1.6], [0.0] * 5), ModelParams()).model.centre_sigma_m == 0
