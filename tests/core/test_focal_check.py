"""The focal-length check on samples measured with a wrong focal length, worked out by hand."""

import math

import pytest

from rangebearing.core.fit import Sample
from rangebearing.core.focal_check import check_focal

TRUE_FX, TRUE_CX = 634.0, 319.5


def samples(fx_cfg, cx_cfg=TRUE_CX, bearings_deg=(-20, -10, 0, 10, 20, 15, -5)):
    """What a camera with fx 634 shows, measured with ``fx_cfg``/``cx_cfg``."""
    out = []
    for i, b in enumerate(bearings_deg):
        u = TRUE_CX - TRUE_FX * math.tan(math.radians(b))  # the column the landmark images to
        meas = math.atan(-(u - cx_cfg) / fx_cfg)
        out.append(Sample(str(i), 50.0, 50.0 / fx_cfg, meas, 0.0, 0.5 + 0.1 * i, math.radians(b)))
    return out


def test_right_focal_length_is_not_suspect():
    c = check_focal(samples(634.0), 634.0, TRUE_CX)
    assert c.fitted and not c.suspect
    assert c.fx_px == pytest.approx(634.0)
    assert c.bearing_err_deg_mean < 1e-9


def test_the_issue_example_530_px_is_caught_and_corrected():
    c = check_focal(samples(530.0), 530.0, TRUE_CX)
    assert c.suspect
    assert c.bearing_err_deg_mean > 1.5
    assert c.fx_px == pytest.approx(634.0, rel=1e-6)
    assert c.cx_px == pytest.approx(TRUE_CX, abs=1e-6)
    assert c.bearing_err_deg_mean_fitted < 1e-6
    assert "fx_px 634.0" in c.message


def test_offset_principal_point_is_found():
    c = check_focal(samples(634.0, cx_cfg=TRUE_CX - 30), 634.0, TRUE_CX - 30)
    assert c.suspect
    assert c.cx_px == pytest.approx(TRUE_CX, abs=1e-6)


def test_without_bearing_spread_nothing_is_fitted_but_a_large_error_is_told():
    c = check_focal(samples(400.0, bearings_deg=(8, 9, 10, 11, 12)), 400.0, TRUE_CX)
    assert not c.fitted and c.suspect
    assert "span 4.0°" in c.message
    ok = check_focal(samples(634.0, bearings_deg=(0, 1, 2, 3)), 634.0, TRUE_CX)
    assert not ok.fitted and not ok.suspect
