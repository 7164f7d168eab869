"""A landmark coming out from behind a followed one is scanned for as it comes out, not at the next scheduled scan."""

from __future__ import annotations

import numpy as np
from tests.core.test_newcomers import BLUE, RED, UNIT, frame, late_frames

from rangebearing.core.newcomers import BESIDE_GAP_PX, beside_count
from rangebearing.core.params import DetectionParams
from rangebearing.synth import LandmarkPose


def paint_landmark(img: np.ndarray, x0: int, x1: int) -> None:
    img[40:50, x0:x1] = RED
    img[50:70, x0:x1] = (230, 230, 230)
    img[70:80, x0:x1] = BLUE


BOX = (60, 40, 20, 40)  # a followed landmark's box: columns 60-79, rows 40-79


def test_red_over_blue_columns_right_beside_a_box_are_counted():
    img = frame()
    paint_landmark(img, BOX[0], BOX[0] + BOX[2])
    assert beside_count(img, DetectionParams(), UNIT, [BOX]) == 0  # the followed landmark itself
    paint_landmark(img, BOX[0] - BESIDE_GAP_PX - 6, BOX[0] - BESIDE_GAP_PX)  # 6 columns left of it
    assert beside_count(img, DetectionParams(), UNIT, [BOX]) == 3  # half-resolution columns
    paint_landmark(img, 82 + BESIDE_GAP_PX, 86 + BESIDE_GAP_PX)  # and 4 on its right
    assert beside_count(img, DetectionParams(), UNIT, [BOX]) == 5


def test_far_from_a_box_or_of_one_colour_counts_nothing():
    img = frame()
    paint_landmark(img, 0, 20)  # more than a box's width away
    paint_landmark(img, 130, 150)
    assert beside_count(img, DetectionParams(), UNIT, [BOX]) == 0
    wall = frame()
    wall[:60] = RED  # a red wall over a grey floor holds no column of both colours
    assert beside_count(wall, DetectionParams(), UNIT, [BOX]) == 0
    assert beside_count(img, DetectionParams(), UNIT, []) == 0


def test_another_followed_landmark_beside_it_is_not_counted():
    img = frame()
    paint_landmark(img, 84, 100)
    assert beside_count(img, DetectionParams(), UNIT, [BOX]) > 0
    assert beside_count(img, DetectionParams(), UNIT, [BOX, (84, 40, 16, 40)]) == 0


def test_a_landmark_uncovered_by_a_nearer_one_driving_off_is_found_as_soon_as_a_full_scan_finds_it():
    # a near landmark drives sideways off a farther one standing behind it: the tracker follows the near one in
    # its window, and nothing comes in at the frame's sides
    late, last = late_frames(lambda i: (LandmarkPose(0.6, 0.02 + 0.004 * i), LandmarkPose(1.2, 0.0)), 24, seed=7)
    assert len(last.landmarks) == 2  # it did come out
    # a full scan every 8 frames alone would leave it unreported for several frames after it came out
    assert late <= 1
