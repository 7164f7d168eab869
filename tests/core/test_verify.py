"""False-landmark checks (core/verify.py): hand-made frames whose answer follows from the paints."""

import dataclasses

import numpy as np
import pytest

from rangebearing.core.detect import BandCentroids
from rangebearing.core.params import ModelParams
from rangebearing.core.structure import Candidate
from rangebearing.core.types import CameraIntrinsics, LandmarkGeometry
from rangebearing.core.verify import percentile, rejection

GEOMETRY = LandmarkGeometry()
RED, WHITE, BLUE = (0.70, 0.07, 0.06), (0.85, 0.85, 0.85), (0.06, 0.12, 0.65)  # linear RGB reflectances
CHASSIS, GREY_WALL = (0.04, 0.04, 0.045), (0.30, 0.30, 0.30)
# a landmark 40 px wide at columns 20-60: red rows 20-35, body rows 35-75, blue rows 75-90 (15/40/15 mm at 1 px/mm)
X0, X1, RED_ROWS, BODY_ROWS, BLUE_ROWS = 20, 60, (20, 35), (35, 75), (75, 90)


def frame(body=WHITE, light=(1.0, 1.0, 1.0), background=GREY_WALL):
    """An 8-bit BGR frame of red / ``body`` / blue strips lit by ``light`` (linear RGB), 2.2-encoded."""
    lin = np.empty((110, 80, 3))
    lin[:] = background
    for rows, paint in ((RED_ROWS, RED), (BODY_ROWS, body), (BLUE_ROWS, BLUE)):
        lin[rows[0] : rows[1], X0:X1] = paint
    lin = np.clip(lin * light, 0.0, 1.0)
    return np.round(255.0 * lin[..., ::-1] ** (1 / 2.2)).astype(np.uint8)


def found(red_merged=False, blue_merged=False):
    red_box = (X0, RED_ROWS[0], X1 - X0, RED_ROWS[1] - RED_ROWS[0])
    blue_box = (X0, BLUE_ROWS[0], X1 - X0, BLUE_ROWS[1] - BLUE_ROWS[0])
    cand = Candidate(red_box, blue_box, 40.0, red_merged, blue_merged, False, False, 1.0)
    centre_x = 0.5 * (X0 + X1) - 0.5
    return BandCentroids((centre_x, 27.0), (centre_x, 82.0), red_box, blue_box, 600.0, 600.0, 90.0, 90.0,
                         candidate=cand)


LIGHTS = [(1.0, 1.0, 1.0), (0.25, 0.25, 0.25), (1.0, 0.7, 0.4), (0.5, 0.7, 1.0)]  # white, dim, warm, cool


@pytest.mark.parametrize("light", LIGHTS)
def test_a_landmark_passes_in_any_light(light):
    assert rejection(frame(light=light), found(), GEOMETRY) is None


@pytest.mark.parametrize("light", LIGHTS)
@pytest.mark.parametrize("body", [CHASSIS, GREY_WALL], ids=["dark-chassis", "grey-wall"])
def test_something_darker_than_the_bands_between_them_is_no_white_body(light, body):
    # a robot's chassis or a grey wall between a red thing and a blue one reads red -> light -> blue in the masks
    assert "darker" in rejection(frame(body=body, light=light), found(), GEOMETRY)


def test_a_mast_in_front_of_part_of_the_white_body_does_not_reject_it():
    img = frame()
    img[BODY_ROWS[0] : BODY_ROWS[1], 30:48] = 12  # a neighbour's dark mast covers 45 % of the body's columns
    assert rejection(img, found(), GEOMETRY) is None


def test_one_merged_band_is_still_a_landmark_but_two_are_not():
    img = frame()
    assert rejection(img, found(red_merged=True), GEOMETRY) is None
    assert rejection(img, found(blue_merged=True), GEOMETRY) is None
    assert "both bands" in rejection(img, found(red_merged=True, blue_merged=True), GEOMETRY)


def test_percentile_is_numpys_linear_percentile():
    rng = np.random.default_rng(3)
    for n in (1, 2, 3, 7, 24, 100, 577):
        for dtype in (np.float32, np.float64):
            v = rng.random((n, 3)).astype(dtype) if n > 1 else np.array([[0.25]], dtype)
            for pct in (0, 10, 50, 75, 90, 99.5, 100):
                assert percentile(v, pct) == pytest.approx(float(np.percentile(v, pct)), rel=1e-6, abs=1e-9)
    ties = np.array([0.2, 0.2, 0.2, 0.9], np.float32)
    assert percentile(ties, 75) == pytest.approx(float(np.percentile(ties, 75)))


def test_percentile_through_a_table_is_the_percentile_of_the_looked_up_values():
    from rangebearing.core.edges import linear_table

    rng = np.random.default_rng(4)
    table = linear_table()
    for n in (1, 2, 5, 24, 576):
        v = rng.integers(0, 256, (n,)).astype(np.uint8)
        for pct in (0, 50, 75, 90, 100):
            assert percentile(v, pct, table) == percentile(table[v], pct)  # the same value, bit for bit


# the test frame at 1 px/mm: band spacing 55 px = the 0.055 m spacing at depth f = 55 px / L_n, with f = 100 px
CAM = CameraIntrinsics(fx_px=100.0, fy_px=100.0, cx_px=40.0, cy_px=54.5)  # the landmark's centre row is 54.5
FITTED = dataclasses.replace(ModelParams(), spacing_m=0.055, centre_sigma_m=0.004)


@pytest.mark.parametrize("centre_below_m, rejected", [(0.0, False), (0.012, False), (-0.012, False),
                                                        (0.04, True), (-0.04, True)])
def test_a_candidate_must_stand_at_the_fitted_height(centre_below_m, rejected):
    # the candidate's centre is on the optical axis (depth 0.1 m here); landmarks stand centre_below_m lower
    model = dataclasses.replace(FITTED, centre_below_m=centre_below_m)
    why = rejection(frame(), found(), GEOMETRY, model, CAM)
    assert (why is not None and "height" in why) == rejected


def test_the_horizon_moves_with_the_cameras_pitch():
    model = dataclasses.replace(FITTED, horizon_y_n=0.4)  # pitched: the horizon 40 px below the centre row
    assert "height" in rejection(frame(), found(), GEOMETRY, model, CAM)
    model = dataclasses.replace(model, centre_below_m=-0.04)  # ... where a landmark 4 cm over the camera is
    assert rejection(frame(), found(), GEOMETRY, model, CAM) is None


def test_with_a_fitted_height_two_merged_bands_at_it_are_a_landmark():
    # a landmark before a red wall over a blue mat: both bands merge, it stands where landmarks stand
    assert rejection(frame(), found(red_merged=True, blue_merged=True), GEOMETRY, FITTED, CAM) is None
    unfitted = dataclasses.replace(FITTED, centre_sigma_m=0.0)
    assert "both bands" in rejection(frame(), found(red_merged=True, blue_merged=True), GEOMETRY, unfitted, CAM)


def striped_frame():
    """The red and white of the landmark run on across the whole frame (a skirting board under a red wall)."""
    img = frame()
    img[RED_ROWS[0] : RED_ROWS[1], :] = img[RED_ROWS[0], X0]
    img[BODY_ROWS[0] : BODY_ROWS[1], :] = img[BODY_ROWS[0], X0]
    return img


def test_red_and_white_running_on_beyond_both_sides_are_stripes_not_a_landmark():
    assert "stripes" in rejection(striped_frame(), found(), GEOMETRY)
    assert rejection(frame(), found(), GEOMETRY) is None


def test_stripes_running_on_beside_one_side_are_stripes_whatever_ends_them_on_the_other():
    # beyond the right side the wall is grey (or a mast stands there): the left still shows red over white
    # at the band's and the body's own rows, which no background beside a real landmark lines up with
    one_side = striped_frame()
    one_side[:, X1 + 2 :] = frame()[:, X1 + 2 :]
    assert "stripes" in rejection(one_side, found(), GEOMETRY)
    assert "stripes" in rejection(masted(striped_frame(), (X1 + 2, X1 + 20)), found(), GEOMETRY)
    # a real landmark before a grey wall with a red poster's edge beside it at its red rows only: no stripes
    poster = frame()
    poster[RED_ROWS[0] : RED_ROWS[1], : X0 - 2] = poster[RED_ROWS[0], X0]
    assert rejection(poster, found(), GEOMETRY) is None


def test_a_touching_neighbour_beside_it_is_no_stripe():
    c = found()
    right = dataclasses.replace(c, red_bbox_px=(X1, *c.red_bbox_px[1:]), blue_bbox_px=(X1, *c.blue_bbox_px[1:]))
    left = dataclasses.replace(c, red_bbox_px=(0, *c.red_bbox_px[1:]), blue_bbox_px=(0, *c.blue_bbox_px[1:]))
    assert rejection(striped_frame(), c, GEOMETRY, others=[c, left, right]) is None


def test_a_neighbour_on_one_side_excuses_only_its_own_columns():
    c = found()
    right = dataclasses.replace(c, red_bbox_px=(X1, *c.red_bbox_px[1:]), blue_bbox_px=(X1, *c.blue_bbox_px[1:]))
    # a skirting board under a red wall runs on to the left; a real landmark stands on the right: stripes
    assert "stripes" in rejection(striped_frame(), c, GEOMETRY, others=[c, right])
    # a narrow neighbour covers under a third of the right strip: what is left of it is judged
    sliver = dataclasses.replace(c, red_bbox_px=(X1 + 6, RED_ROWS[0], 4, 15),
                                 blue_bbox_px=(X1 + 6, BLUE_ROWS[0], 4, 15))
    right_only = striped_frame()
    right_only[:, : X0 - 2] = frame()[:, : X0 - 2]  # left of it the wall is grey: only the right side can tell
    assert "stripes" in rejection(right_only, c, GEOMETRY, others=[c, sliver])
    assert rejection(frame(), c, GEOMETRY, others=[c, sliver]) is None


def wide(img, width=200, at=80):
    """``img`` (the 80-px frames above) with its columns 0-80 placed at ``at`` in a frame ``width`` wide,
    its first and last columns repeated outwards (a background that runs on)."""
    out = np.repeat(img[:, :1], width, axis=1)
    out[:, at + 80 :] = img[:, -1:]
    out[:, at : at + 80] = img
    return out


def shifted(c, dx):
    return dataclasses.replace(c, red_xy_px=(c.red_xy_px[0] + dx, c.red_xy_px[1]),
                               blue_xy_px=(c.blue_xy_px[0] + dx, c.blue_xy_px[1]),
                               red_bbox_px=(c.red_bbox_px[0] + dx, *c.red_bbox_px[1:]),
                               blue_bbox_px=(c.blue_bbox_px[0] + dx, *c.blue_bbox_px[1:]))


MAST = (0.03, 0.03, 0.035)  # a robot's dark mast and camera board


def masted(img, cols):
    """``img`` with a dark mast over the columns ``cols`` from the top of the red band down."""
    out = img.copy()
    out[RED_ROWS[0] :, cols[0] : cols[1]] = np.round(255.0 * np.array(MAST[::-1]) ** (1 / 2.2)).astype(np.uint8)
    return out


def cut(c):
    """``c`` with its run cut on both sides (ended by something other than its limbs: here, masts)."""
    return dataclasses.replace(c, candidate=dataclasses.replace(c.candidate, cut_left=True, cut_right=True))


def test_stripes_running_on_beyond_a_mast_beside_it_are_still_stripes():
    c = cut(shifted(found(), 80))  # the landmark's columns 100-140 in a frame 200 px wide
    stripes = wide(striped_frame())
    # a mast right beside each side (0.15-0.6 of the width out) hides the stripes there, not beyond
    beside = masted(masted(stripes, (80, 96)), (144, 160))
    assert "stripes" in rejection(beside, c, GEOMETRY)
    # a run that ends at its limbs is judged right beside them (what lies there is what is beside it)
    assert rejection(beside, shifted(found(), 80), GEOMETRY) is None
    # a real landmark between two masts before a grey wall: nothing runs on
    assert rejection(masted(masted(wide(frame()), (80, 96)), (144, 160)), c, GEOMETRY) is None
    # ... nor before a skirting board that ends at the masts (grey wall beyond them)
    ends = beside.copy()
    ends[:, :80], ends[:, 160:] = wide(frame())[:, :80], wide(frame())[:, 160:]
    assert rejection(ends, c, GEOMETRY) is None


def test_a_neighbour_beyond_a_mast_is_no_stripe():
    c = cut(shifted(found(), 80))
    stripes = masted(wide(striped_frame()), (144, 160))
    left = shifted(c, -44)  # a landmark right beside its left side (columns 56-96): only the right is judged
    neighbour = shifted(c, 62)  # another candidate at the stripes' rows beyond the mast (columns 162-202)
    assert "stripes" in rejection(stripes, c, GEOMETRY, others=[c, left])  # the stripes beyond the mast
    assert rejection(stripes, c, GEOMETRY, others=[c, left, neighbour]) is None  # a neighbour's own bands and body
