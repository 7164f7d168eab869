"""Columns of landmarks cut at one side: limbs and outline centres (core/measure.py, core/edges.limb)."""

import dataclasses
import math

import numpy as np
import pytest

from rangebearing import Pipeline, load_config
from rangebearing.core.band_seed import seeded_band
from rangebearing.core.limb_edge import limb
from rangebearing.core.limbs import moments_outline
from rangebearing.core.measure import measure_rows, outline_centre
from rangebearing.core.structure import Candidate
from rangebearing.core.types import LandmarkGeometry
from rangebearing.synth import Imaging, LandmarkPose, Scene, render

GEOMETRY = LandmarkGeometry()
NOISE = Imaging(blur_sigma_px=0.6, read_noise=0.004, shot_noise=0.0006)


@pytest.mark.parametrize("phi_rad", [-0.42, -0.1, 0.0, 0.25, 0.45])
@pytest.mark.parametrize("range_m", [0.22, 0.6, 1.5])
def test_outline_centre_from_either_limb_is_the_mean_of_the_two_tangent_images(phi_rad, range_m):
    f, cx = 634.0, 319.5
    r = GEOMETRY.radius_m
    alpha = math.asin(r / range_m)
    left, right = (cx + f * math.tan(phi_rad + s * alpha) for s in (-1, 1))
    # the white height as the camera sees it on the near surface, depth (d − r)·cos φ
    white_m = GEOMETRY.height_m - 2 * GEOMETRY.band_height_m
    white_px = f * white_m / ((range_m - r) * math.cos(phi_rad))
    centre = 0.5 * (left + right)
    assert outline_centre(right, True, cx, f, white_px, GEOMETRY) == pytest.approx(centre, abs=1e-3)
    assert outline_centre(left, False, cx, f, white_px, GEOMETRY) == pytest.approx(centre, abs=1e-3)


def _band_moment(phi_rad, range_m, f, cx):
    """Column of a band's area moment on the visible half of the cylinder: each image column weighted
    by the band's height there, ``∝ 1/Z`` of the surface point it shows."""
    r = GEOMETRY.radius_m
    ax, az = range_m * math.sin(phi_rad), range_m * math.cos(phi_rad)
    t = np.linspace(0.0, 2.0 * math.pi, 400001)
    px, pz = ax + r * np.sin(t), az + r * np.cos(t)
    seen = np.sin(t) * px + np.cos(t) * pz < 0.0  # the surface's normal faces the camera
    x, z = px[seen] / pz[seen], pz[seen]
    order = np.argsort(x)
    x, z = x[order], z[order]
    w = np.gradient(x) / z
    return cx + f * float(np.sum(x * w) / np.sum(w))


@pytest.mark.parametrize("phi_rad", [-0.42, 0.0, 0.25, 0.45])
@pytest.mark.parametrize("range_m", [0.22, 0.4, 1.0])
def test_moments_outline_takes_the_bands_moment_to_the_outline_centre(phi_rad, range_m):
    f, cx = 634.0, 319.5
    r = GEOMETRY.radius_m
    alpha = math.asin(r / range_m)
    centre = 0.5 * sum(cx + f * math.tan(phi_rad + s * alpha) for s in (-1, 1))
    white_m = GEOMETRY.height_m - 2 * GEOMETRY.band_height_m
    white_px = f * white_m / ((range_m - r) * math.cos(phi_rad))
    moment = _band_moment(phi_rad, range_m, f, cx)
    shift = moment - centre  # outward off the axis: 0.2-0.9 px this near
    assert shift * phi_rad >= 0.0 and (phi_rad == 0.0 or range_m > 0.5 or abs(shift) > 0.1)
    corrected = moments_outline(moment, cx, f, white_px, GEOMETRY)
    assert abs(corrected - centre) <= 0.1 * abs(shift) + 1e-3


def _profile(n, edge, level, bg):
    """A band of ``level`` up to column ``edge`` (sub-pixel, linear mixing), ``bg`` beyond."""
    cols = np.arange(n, dtype=np.float64)
    cover = np.clip(edge - (cols - 0.5), 0.0, 1.0)
    return bg + (level - bg) * cover


@pytest.mark.parametrize("edge", [20.0, 20.3, 20.75])
def test_limb_is_the_two_level_edge_going_either_way(edge):
    p = _profile(40, edge, 0.7, 0.02)
    assert limb(p, 5, 39, 0.7) == pytest.approx(edge, abs=1e-6)
    q = p[::-1].copy()  # the mirror image: the limb at 39 − edge, searched leftwards
    assert limb(q, 34, 0, 0.7) == pytest.approx(39 - edge, abs=1e-6)


def test_limb_stops_before_a_neighbours_band_of_the_same_colour():
    p = _profile(40, 20.3, 0.7, 0.0)
    p[27:] = 0.3  # a neighbour's band, only partly in these rows, starts a few columns beyond
    assert limb(p, 5, 39, 0.7) == pytest.approx(20.3, abs=1e-6)


def test_limb_is_nan_where_the_band_never_falls():
    assert math.isnan(limb(np.full(30, 0.7), 3, 29, 0.7))


def _bearings(*poses):
    img = render(Scene(landmarks=tuple(poses), imaging=NOISE, wall_distance_m=2.5), np.random.default_rng(3))
    found = Pipeline(load_config(None).pipeline, track=False).process(img).landmarks
    return found


@pytest.mark.parametrize("bearing_rad", [0.462, -0.462])
def test_a_landmark_cut_by_the_frame_edge_is_placed_from_its_inner_limb(bearing_rad):
    # at 0.3 m the frame edge (±26.8°) cuts about a third of the silhouette off
    (lm,) = _bearings(LandmarkPose(0.3, bearing_rad))
    assert lm.visible < 0.9
    assert math.degrees(abs(lm.bearing_rad - bearing_rad)) < 0.15
    assert lm.range_m == pytest.approx(0.3, rel=0.01)


def _strips(hidden_rows=0):
    """A crisp landmark 40 px wide: red rows 20-35, white 35-75, blue 75-90; a dark robot body in front
    hides the blue band's last ``hidden_rows`` rows."""
    lin = np.full((120, 80, 3), 0.30)
    for (r0, r1), rgb in (((20, 35), (0.70, 0.07, 0.06)), ((35, 75), (0.85,) * 3), ((75, 90), (0.06, 0.12, 0.65))):
        lin[r0:r1, 20:60] = rgb
    lin[90 - hidden_rows : 110, 10:70] = 0.04
    return np.round(255.0 * lin[..., ::-1] ** (1 / 2.2)).astype(np.uint8)


def _candidate():
    return Candidate((20, 20, 40, 15), (20, 76, 40, 15), 40.0, False, False, False, False, 1.0)


def test_a_whole_band_is_placed_between_its_edges():
    rows = measure_rows(_strips(), _candidate(), (1.0, 1.0, 1.0), GEOMETRY, 39.5)
    assert rows.red_y_px == pytest.approx(27.0, abs=0.05) and rows.blue_y_px == pytest.approx(82.0, abs=0.05)
    assert not rows.blue_merged and rows.blue_px == pytest.approx(15.0, abs=0.1)


@pytest.mark.parametrize("hidden_rows", [4, 7])
def test_a_blue_band_hidden_from_below_is_placed_from_its_inner_edge(hidden_rows):
    # between its edges the band's centre would be (75 + 90 − hidden)/2: 3.5 px, 6 % of L, too high at 7 rows hidden
    rows = measure_rows(_strips(hidden_rows), _candidate(), (1.0, 1.0, 1.0), GEOMETRY, 39.5)
    assert rows.blue_merged
    assert rows.blue_y_px == pytest.approx(82.0, abs=0.1)


def test_a_band_whose_edges_fit_the_landmark_takes_its_edges_row_else_the_mean_with_its_moment():
    rows = measure_rows(_strips(), _candidate(), (1.0, 1.0, 1.0), GEOMETRY, 39.5)
    assert rows.red_fits and rows.blue_fits
    assert rows.band_y(True, 30.0) == rows.red_y_px and rows.band_y(False, 80.0) == rows.blue_y_px
    off = dataclasses.replace(rows, red_px=0.7 * rows.red_px, red_fits=False)
    assert off.band_y(True, 30.0) == pytest.approx(0.5 * (30.0 + rows.red_y_px))


def test_a_dark_band_before_a_background_of_half_its_level_is_measured_on_its_own_rows():
    # a backlit red band (level 0.68) under a warm wall whose red excess is half of it (0.35): the band's run
    # of strong colour runs through the wall; seeded on the run's centre the band read as merged, its level
    # half the wall's and its inner edge a row into the white body
    p = np.zeros(40, np.float32)
    p[:14] = 0.35
    p[14:20] = 0.68  # the band: rows 14-19, inner edge at 19.5
    p2d = np.repeat(p[:, None], 8, axis=1)
    band = seeded_band(p2d, p, 16.5, 5.25, 14.0, True, False)
    assert band.inner == pytest.approx(19.5, abs=0.05)
