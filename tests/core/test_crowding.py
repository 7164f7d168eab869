"""Candidates closer than two robots can stand (core/crowding.py): distances worked out by hand."""

import math

import pytest

from rangebearing.core.crowding import CROWDED, ROBOT_APART_M, apart_m, crowded_out
from rangebearing.core.detect import BandCentroids
from rangebearing.core.types import CameraIntrinsics, LandmarkGeometry

GEOMETRY = LandmarkGeometry()  # band centres 0.055 m apart
# f = 100 px: a band spacing of 55 px puts a landmark 0.1 m away, where one pixel across is one millimetre
CAM = CameraIntrinsics(fx_px=100.0, fy_px=100.0, cx_px=200.0, cy_px=100.0)


def at(x_px, red_y_px=70.0, spacing_px=55.0):
    """A candidate whose band centroids stand at column ``x_px``, the red one at ``red_y_px``."""
    red_box, blue_box = (x_px - 17, red_y_px - 7, 35, 15), (x_px - 17, red_y_px + spacing_px - 7, 35, 15)
    return BandCentroids((x_px, red_y_px), (x_px, red_y_px + spacing_px), red_box, blue_box,
                         500.0, 500.0, 90.0, 90.0)


def test_apart_is_the_lateral_distance_and_the_spacings_depth_combined():
    # 30 px across at 0.1 m: 30 mm; spacings alike: only their noise, 0.5 px of 55 at 0.1 m deep (0.91 mm)
    assert apart_m(at(200), at(230), GEOMETRY, CAM) == pytest.approx(math.hypot(0.030, 0.1 * 0.5 / 55))
    # one behind the other on one bearing: spacings 55 and 50 px put them 0.1 * 5.5 / 55 m apart in depth
    assert apart_m(at(200), at(200, spacing_px=50.0), GEOMETRY, CAM) == pytest.approx(0.1 * 5.5 / 55)


def test_of_two_closer_than_robots_stand_the_one_off_the_landmarks_height_goes():
    found = [at(200), at(230, red_y_px=74.0)]  # 3 cm apart at one depth
    for offs, dropped in (([0.001, 0.03], 1), ([-0.03, 0.002], 0)):
        why = crowded_out(found, offs, [None, None], GEOMETRY, CAM)
        assert why[dropped] == CROWDED and why[1 - dropped] is None
    # whatever the order they come in
    assert crowded_out(found[::-1], [0.03, 0.001], [None, None], GEOMETRY, CAM) == [CROWDED, None]


@pytest.mark.parametrize("other", [at(200 + 1000 * ROBOT_APART_M + 5),  # beside it, a robot's width away
                                   at(215, spacing_px=20.0)],  # nearly on its bearing, far behind it
                         ids=["robot-apart", "behind"])
def test_landmarks_that_robots_can_carry_both_stay(other):
    assert crowded_out([at(200), other], [0.0, 0.03], [None, None], GEOMETRY, CAM) == [None, None]


def test_a_rejected_candidate_crowds_out_none_and_each_is_judged_against_those_kept():
    # the middle one is nearest the height; each neighbour 4.5 cm from it, 9 cm from each other
    found = [at(155), at(200), at(245)]
    assert crowded_out(found, [0.02, 0.0, 0.02], [None, None, None], GEOMETRY, CAM) == [CROWDED, None, CROWDED]
    stripes = "stripes"
    assert crowded_out(found, [0.02, 0.0, 0.02], [None, stripes, None], GEOMETRY, CAM) == [None, stripes, None]
