import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rangebearing.core.model import axis_bearing, in_envelope, normalised, paper_reading, pinhole_reading
from rangebearing.core.params import ModelParams
from rangebearing.core.types import CameraIntrinsics, LandmarkGeometry

CAM = CameraIntrinsics()
GEO = LandmarkGeometry()
PIN = ModelParams()
PAPER = dataclasses.replace(ModelParams(), kind="paper", k_px_m=35.0, kh_m_per_px=0.00079)

offsets = st.floats(min_value=-300, max_value=300, allow_nan=False).filter(lambda v: abs(v) > 1e-6)
lengths = st.floats(min_value=15, max_value=250, allow_nan=False)


def centroids(dx, L, cam=CAM):
    x = cam.cx_px + dx
    return (x, cam.cy_px - L / 2), (x, cam.cy_px + L / 2)


@pytest.mark.parametrize("model", [PIN, PAPER])
def test_bearing_is_zero_at_the_principal_point(model):
    r, b = centroids(0.0, 80)
    fn = pinhole_reading if model.kind == "pinhole" else lambda *a: paper_reading(*a[:4])
    assert fn(r, b, CAM, model, GEO)[1] == 0.0


@given(dx=offsets, L=lengths)
def test_pinhole_bearing_is_odd_symmetric_and_positive_left(dx, L):
    r1, b1 = centroids(dx, L)
    r2, b2 = centroids(-dx, L)
    _, left, *_ = pinhole_reading(r1, b1, CAM, PIN, GEO)
    _, right, *_ = pinhole_reading(r2, b2, CAM, PIN, GEO)
    assert left == pytest.approx(-right, abs=1e-12)
    if dx < 0:  # landmark left of centre → positive bearing
        assert left > 0


@given(dx1=offsets, dx2=offsets, L=lengths)
def test_pinhole_bearing_is_monotonic_in_pixel_offset(dx1, dx2, L):
    if abs(dx1 - dx2) < 1e-6:
        return
    b1 = pinhole_reading(*centroids(dx1, L), CAM, PIN, GEO)[1]
    b2 = pinhole_reading(*centroids(dx2, L), CAM, PIN, GEO)[1]
    assert (b1 > b2) == (dx1 < dx2)


@given(L1=lengths, L2=lengths, dx=offsets)
def test_range_falls_as_L_grows(L1, L2, dx):
    if abs(L1 - L2) < 1e-6:
        return
    for model in (PIN, PAPER):
        r1 = (
            pinhole_reading(*centroids(dx, L1), CAM, model, GEO)
            if model is PIN
            else paper_reading(*centroids(dx, L1), CAM, model)
        )[0]
        r2 = (
            pinhole_reading(*centroids(dx, L2), CAM, model, GEO)
            if model is PIN
            else paper_reading(*centroids(dx, L2), CAM, model)
        )[0]
        assert (r1 > r2) == (L1 < L2)


def test_paper_model_by_hand():
    # L = 100 px → d_v = 3500/100 cm = 0.35 m; 50 px left → d_h = 0.0395 m
    r, b = centroids(-50, 100)
    rng, th, d_v, d_h, L = paper_reading(r, b, CAM, PAPER)
    assert pytest.approx(100) == L
    assert d_v == pytest.approx(0.35)
    assert d_h == pytest.approx(0.0395)
    assert th == pytest.approx(math.atan(0.0395 / 0.35))
    assert rng == pytest.approx(0.35 / math.cos(th))


def test_pinhole_model_by_hand():
    # on the axis: range = k/L + c
    r, b = centroids(0, 100)
    rng, _th, d_v, d_h, _L = pinhole_reading(r, b, CAM, PIN, GEO)
    assert rng == pytest.approx(PIN.spacing_m * CAM.fy_px / 100 + PIN.c_m)
    assert d_h == pytest.approx(0.0) and d_v == pytest.approx(rng)


@given(theta=st.floats(min_value=-0.5, max_value=0.5), rng=st.floats(min_value=0.1, max_value=3.0))
def test_axis_bearing_inverts_the_outline_centre(theta, rng):
    alpha = math.asin(GEO.radius_m / rng)
    centre = math.atan(0.5 * (math.tan(theta - alpha) + math.tan(theta + alpha)))
    assert axis_bearing(centre, rng, GEO.radius_m) == pytest.approx(theta, abs=1e-9)


def test_normalised_undoes_distortion():
    import cv2

    cam = dataclasses.replace(CAM, distortion=(-0.2, 0.05, 0.0, 0.0, 0.0))
    k = np.array([[cam.fx_px, 0, cam.cx_px], [0, cam.fy_px, cam.cy_px], [0, 0, 1.0]])
    ideal = np.array([[0.3, -0.2], [-0.35, 0.1], [0.0, 0.0]])
    pts, _ = cv2.projectPoints(
        np.column_stack((ideal, np.ones(3))), np.zeros(3), np.zeros(3), k, np.array(cam.distortion)
    )
    assert normalised(pts.reshape(-1, 2), cam) == pytest.approx(ideal, abs=1e-6)


def test_envelope():
    assert in_envelope(0.5, 0.0, PIN)
    assert not in_envelope(2.5, 0.0, PIN)
    assert not in_envelope(0.5, 0.6, PIN)
