"""The band spacing over part of a cylinder's width (core/arc.py): edges are arcs, nearer at the middle."""

import math

import numpy as np
import pytest

from rangebearing.core.arc import arc_scale
from rangebearing.core.types import LandmarkGeometry

G = LandmarkGeometry()
F_PX, CX_PX = 634.0, 319.5
WHITE_M = G.height_m - 2 * G.band_height_m


def _white_px(d_m: float) -> float:
    """The white height a landmark whose axis lies ``d_m`` straight ahead shows (its near surface)."""
    return F_PX * WHITE_M / (d_m - G.radius_m)


def _outline(d_m: float, axis_px: float):
    """Brute force: image columns and 1/Z of the visible front of the circle, from every surface point
    whose outward normal faces the camera."""
    phi = math.atan((axis_px - CX_PX) / F_PX)
    xc, zc = d_m * math.sin(phi), d_m * math.cos(phi)
    t = np.linspace(-math.pi, math.pi, 200001)
    x, z = xc + G.radius_m * np.sin(t), zc - G.radius_m * np.cos(t)
    front = x * np.sin(t) - z * np.cos(t) + G.radius_m < 0  # P·n < 0: the camera sees the outside
    order = np.argsort(x[front] / z[front])
    return CX_PX + F_PX * (x[front] / z[front])[order], (1.0 / z[front])[order]


def test_the_whole_landmarks_middle_window_needs_no_correction():
    d = 0.4
    u, _ = _outline(d, CX_PX)
    width = u[-1] - u[0]
    k = arc_scale((CX_PX - width / 3, CX_PX + width / 3), CX_PX, CX_PX, F_PX, _white_px(d), G)
    assert k == pytest.approx(1.0, abs=2e-3)


def _mean(u, w, lo, hi):
    return np.interp(np.linspace(lo, hi, 2001), u, w).mean()


@pytest.mark.parametrize("d", [0.2, 0.5, 1.5])
@pytest.mark.parametrize("bearing_deg", [0.0, -25.0])
def test_columns_towards_a_limb_see_a_shorter_spacing_by_the_surfaces_depth(d, bearing_deg):
    # the right half only shows (a nearer landmark hides the left one); 25 deg right of the axis too, where the
    # surface's nearest point (least depth Z) lies right of the outline's centre
    axis_px = CX_PX + F_PX * math.tan(math.radians(-bearing_deg))
    u, w = _outline(d, axis_px)
    centre, width = 0.5 * (u[0] + u[-1]), u[-1] - u[0]
    expected = _mean(u, w, centre - width / 3, centre + width / 3) / _mean(u, w, centre, u[-1])
    white_px = F_PX * WHITE_M / ((d - G.radius_m) * math.cos(math.radians(bearing_deg)))
    k = arc_scale((centre, u[-1]), centre, CX_PX, F_PX, white_px, G)
    assert k == pytest.approx(expected, rel=1e-3)
    if bearing_deg == 0.0:  # straight ahead the surface is nearest at the middle (off the axis, towards the side)
        assert k > 1.0


def test_the_correction_is_mirror_symmetric_and_grows_near_the_camera():
    near = arc_scale((300.0, 360.0), 300.0, CX_PX, F_PX, _white_px(0.25), G)
    mirror = arc_scale((240.0, 300.0), 300.0, 2 * 300.0 - CX_PX, F_PX, _white_px(0.25), G)
    assert near == pytest.approx(mirror, rel=1e-6)
    far = arc_scale((300.0, 307.0), 300.0, CX_PX, F_PX, _white_px(1.5), G)
    assert near > far > 1.0


def test_columns_that_miss_the_outline_leave_the_spacing_alone():
    assert arc_scale((500.0, 520.0), 300.0, CX_PX, F_PX, _white_px(0.5), G) == 1.0
