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


def _reference_count(img: np.ndarray, cfg: DetectionParams, boxes: list) -> int:
    """beside_count spelled out one strip at a time: every other column and row of each strip, the followed
    boxes' columns left out."""
    from rangebearing.core.color import class_masks, to_hsv
    from rangebearing.core.newcomers import MIN_PX

    h, w = img.shape[:2]
    count = 0
    for bx, by, bw, bh in boxes:
        y0, y1 = max(0, by - bh // 2), min(h, by + bh + bh // 2)
        left, right = bx - BESIDE_GAP_PX, bx + bw + BESIDE_GAP_PX
        for x0, x1 in ((left - bw, left), (right, right + bw)):
            x0, x1 = max(0, x0), min(w, x1)
            if x1 - x0 < 2 or y1 - y0 < 2:
                continue
            red, blue = class_masks(to_hsv(img[y0:y1:2, x0:x1:2]), cfg.red_hue, cfg.blue_hue, cfg.s_min, cfg.v_min)
            for k, x in enumerate(range(x0, x1, 2)):
                if any(ox <= x < ox + ow for ox, _, ow, _ in boxes):
                    continue
                count += np.count_nonzero(red[:, k]) >= MIN_PX and np.count_nonzero(blue[:, k]) >= MIN_PX
    return count


def test_the_count_is_each_strips_columns_of_both_colours_outside_every_followed_box():
    rng = np.random.default_rng(11)
    cfg, counted = DetectionParams(), 0
    for _ in range(40):
        img = frame()
        for _ in range(12):  # blocks of band colours and white, some beside and inside the boxes
            y, x, colour = rng.integers(0, 120), rng.integers(0, 160), (RED, BLUE, (230, 230, 230))[rng.integers(3)]
            img[y : y + rng.integers(2, 25), x : x + rng.integers(2, 25)] = colour
        boxes = [(int(rng.integers(-10, 150)), int(rng.integers(-10, 110)), int(rng.integers(4, 40)),
                  int(rng.integers(4, 60))) for _ in range(rng.integers(1, 5))]
        want = _reference_count(img, cfg, boxes)
        assert beside_count(img, cfg, UNIT, boxes) == want
        counted += want
    assert counted > 0
