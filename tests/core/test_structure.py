"""The structure search: red→white→blue columns, runs of continuous edges, splitting and cut sides."""

import numpy as np
import pytest

from rangebearing.core.color import to_hsv
from rangebearing.core.structure import (
    MAX_REGIONS,
    band_regions,
    column_edges,
    region_pairs,
    region_stats,
    runs,
)
from rangebearing.core.structure import search as structure_search
from rangebearing.core.types import LandmarkGeometry

RED, BLUE, WHITE, GREY = (40, 40, 200), (200, 60, 30), (220, 220, 220), (120, 120, 120)
GEOMETRY = LandmarkGeometry()


def column(*rows):
    """A one-column (N, 1) bool mask from a string of r/b/w/. characters, for each class."""
    s = "".join(rows)
    return tuple(np.array([[c == k] for c in s]) for k in "rbw")


def test_column_edges_find_the_inner_edges_and_band_runs():
    red, blue, white = column("..rr", "wwww", "bb..")
    ok, y1, y2, run_r, run_b = column_edges(red, blue, white)
    assert ok.tolist() == [True] and (y1[0], y2[0]) == (3, 8) and (run_r[0], run_b[0]) == (2, 2)


@pytest.mark.parametrize(
    "pattern",
    [
        "rr..bb",  # nothing white between: a red box beside a blue one
        "bbwwrr",  # blue above red
        "rrwbb.",  # one white row: too thin for a white body
    ],
)
def test_columns_without_red_white_blue_are_rejected(pattern):
    ok = column_edges(*column(pattern))[0]
    assert ok.tolist() == [False]


def test_the_whitest_pair_of_edges_wins_in_a_column():
    # a red box high up, grey floor, then the landmark's own red band, white body, blue band
    red, blue, white = column("rr...rr", "wwww", "bb")
    ok, y1, y2, _, _ = column_edges(red, blue, white)
    assert ok[0] and (y1[0], y2[0]) == (6, 11)


def test_runs_break_where_an_edge_jumps():
    ok = np.array([True] * 6 + [False] + [True] * 3)
    y1 = np.array([10, 10, 11, 10, 20, 20, 0, 5, 5, 5])
    y2 = np.array([30, 30, 30, 31, 40, 40, 0, 15, 15, 15])
    assert runs(ok, y1, y2) == [(0, 4), (4, 6), (7, 10)]


def landmark(img, x0, y0, band, width):
    """Paint a flat landmark (band, 40/15·band white, band) into a BGR image."""
    white = round(band * 40 / 15)
    img[y0 : y0 + band, x0 : x0 + width] = RED
    img[y0 + band : y0 + band + white, x0 : x0 + width] = WHITE
    img[y0 + band + white : y0 + 2 * band + white, x0 : x0 + width] = BLUE


def search(img, max_landmarks=16):
    hsv = to_hsv(img)
    red = ((hsv[..., 0] < 10) & (hsv[..., 1] > 90)).astype(np.uint8) * 255
    blue = ((hsv[..., 0] > 98) & (hsv[..., 0] < 132) & (hsv[..., 1] > 90)).astype(np.uint8) * 255
    return structure_search(red, blue, hsv, 1, GEOMETRY, max_landmarks).candidates


def test_one_landmark_is_one_whole_candidate():
    img = np.full((120, 160, 3), GREY, np.uint8)
    landmark(img, 50, 20, 9, 21)  # 9 px bands, 24 px white: a silhouette of 21 columns
    (c,) = search(img)
    assert c.red_bbox_px == (50, 20, 21, 9) and c.blue_bbox_px == (50, 53, 21, 9)
    assert c.white_px == 24 and c.visible == pytest.approx(1.0)
    assert not (c.red_merged or c.blue_merged or c.cut_left or c.cut_right)


def test_two_touching_landmarks_at_one_range_are_split_with_their_inner_sides_cut():
    img = np.full((120, 160, 3), GREY, np.uint8)
    landmark(img, 40, 20, 9, 21)
    landmark(img, 61, 20, 9, 21)  # touching: one red region, one blue region, 42 columns
    left, right = sorted(search(img), key=lambda c: c.red_bbox_px[0])
    assert left.red_bbox_px[0] == 40 and right.red_bbox_px[0] == 61
    assert (left.cut_left, left.cut_right, right.cut_left, right.cut_right) == (False, True, True, False)


def test_a_landmark_half_hidden_behind_a_nearer_one_keeps_its_visible_columns():
    img = np.full((160, 200, 3), GREY, np.uint8)
    landmark(img, 70, 35, 6, 14)  # far one, 14 columns wide
    landmark(img, 78, 20, 12, 28)  # near one in front, covering the far one's right part
    found = sorted(search(img), key=lambda c: c.white_px)
    far, near = found
    assert near.white_px == 32 and near.visible == pytest.approx(1.0)
    assert far.white_px == 16 and far.red_bbox_px[0] == 70 and far.red_bbox_px[2] == 8
    assert far.cut_right and not far.cut_left and far.visible == pytest.approx(9 / 14)


def test_a_red_box_on_top_of_the_band_marks_it_merged():
    img = np.full((120, 160, 3), GREY, np.uint8)
    img[0:20, 30:100] = RED  # a red box behind, touching the band's top
    landmark(img, 50, 20, 9, 21)
    (c,) = search(img)
    assert c.red_merged and not c.blue_merged
    assert not (c.cut_left or c.cut_right)  # the box ends above the band: its sides are still limbs


def test_a_wide_red_white_blue_stripe_is_no_landmark():
    img = np.full((120, 200, 3), GREY, np.uint8)
    img[20:40, 10:190] = RED  # a poster above a white wall above a blue mat
    img[40:64, 10:190] = WHITE
    img[64:90, 10:190] = BLUE
    assert search(img) == []


def stack(img, x0, y0, red, white, blue, width):
    """Paint red over white over blue stripes of the given heights."""
    img[y0 : y0 + red, x0 : x0 + width] = RED
    img[y0 + red : y0 + red + white, x0 : x0 + width] = WHITE
    img[y0 + red + white : y0 + red + white + blue, x0 : x0 + width] = BLUE


def test_a_stack_whose_bands_are_both_far_thinner_than_its_body_gives_is_no_landmark():
    img = np.full((120, 160, 3), GREY, np.uint8)
    stack(img, 50, 20, 3, 32, 3, 28)  # 32 px white wants 12 px bands and 28 columns: a flag's thin stripes
    assert search(img) == []


def test_one_band_thinned_by_something_in_front_of_it_keeps_the_landmark():
    img = np.full((120, 160, 3), GREY, np.uint8)
    stack(img, 50, 20, 12, 32, 3, 28)  # the blue band hidden but for 3 rows (a nearer thing below it)
    (c,) = search(img)
    assert c.white_px == 32 and not (c.red_merged or c.blue_merged)


def test_the_search_is_bounded_by_max_landmarks_and_the_region_cap():
    img = np.full((480, 640, 3), GREY, np.uint8)
    for i in range(8):
        for j in range(12):
            landmark(img, 10 + 52 * j, 5 + 58 * i, 6, 14)
    assert len(search(img, max_landmarks=16)) == 16
    specks = np.zeros((480, 640), np.uint8)
    specks[2::6, 2::6] = 255  # 80 x 107 one-pixel specks ...
    specks[100:103, 100:104] = 255  # ... and one region larger than all of them
    reds = region_stats(specks, 1)
    assert len(reds) == MAX_REGIONS and reds[:, 5].max() == 12  # the largest regions, that one included
    assert len(region_pairs(reds, reds, 10)) <= 10


def test_the_region_cap_keeps_a_far_band_with_blue_below_before_bigger_floor_blotches():
    # a floor laced with red (more red regions than the cap, each bigger than a far band) and
    # one far landmark: its small red band has blue under it, the blotches do not
    img = np.full((240, 320, 3), GREY, np.uint8)
    for i in range(12):
        for j in range(16):
            img[120 + 10 * i : 124 + 10 * i, 4 + 20 * j : 12 + 20 * j] = RED  # 4 x 8 blotches
    landmark(img, 150, 40, 3, 5)  # 3 x 5 bands: a landmark about 2 m away at half resolution
    hsv = to_hsv(img)
    red = ((hsv[..., 0] < 10) & (hsv[..., 1] > 90)).astype(np.uint8) * 255
    blue = ((hsv[..., 0] > 98) & (hsv[..., 0] < 132) & (hsv[..., 1] > 90)).astype(np.uint8) * 255
    assert len(region_stats(red, 2, cap=False)) > MAX_REGIONS
    assert not any(r[1] == 150 for r in region_stats(red, 2))  # by area alone the band is dropped
    reds, blues = band_regions(red, blue, 2)
    assert len(blues) == 1
    assert len(reds) == MAX_REGIONS and any(r[1] == 150 and r[2] == 40 for r in reds)
    assert [c.red_bbox_px[0] for c in structure_search(red, blue, hsv, 1, GEOMETRY, 4).candidates] == [150]


def test_a_band_merged_with_a_red_thing_reaching_below_the_landmark_is_still_paired():
    # a red poster beside the landmark touches its band and reaches below the blue band:
    # the red region's box ends below the blue one's
    img = np.full((120, 160, 3), GREY, np.uint8)
    img[15:90, 10:50] = RED
    landmark(img, 50, 20, 9, 21)
    (c,) = search(img)
    assert c.red_bbox_px[0] == 50 and c.white_px == 24 and c.cut_left and not c.cut_right


def test_a_band_merged_with_a_red_floor_below_is_still_paired():
    img = np.full((120, 160, 3), GREY, np.uint8)
    landmark(img, 50, 20, 9, 21)
    img[62:120, 0:160] = RED  # a red floor right under the blue band, wider than the landmark
    img[20:29, 71:75] = RED  # ... and joined to the red band by a red thing beside it
    img[29:62, 71:75] = RED
    (c,) = search(img)
    assert c.red_bbox_px[:3] == (50, 20, 21) and c.white_px == 24


def test_a_nearer_landmark_beside_a_farther_one_is_cut_where_the_white_height_steps():
    # the far one peeks out on the left; its edges are 2 rows inside the near one's: no jump
    img = np.full((120, 160, 3), GREY, np.uint8)
    img[24:31, 38:50] = RED  # far: 7-row band, 20-row white body (silhouette 17.5 columns), 12 seen
    img[31:51, 38:50] = WHITE
    img[51:58, 38:50] = BLUE
    landmark(img, 50, 20, 9, 21)  # near: 24-row white body, 21 columns
    found = sorted(search(img), key=lambda c: c.red_bbox_px[0])
    assert [c.white_px for c in found] == [20, 24]
    far, near = found
    assert near.red_bbox_px[0] == 50 and near.red_bbox_px[2] == 21 and near.visible == pytest.approx(1.0)
    assert far.red_bbox_px[0] == 38 and far.cut_right and not far.cut_left and far.visible < 0.9


def test_a_landmark_behind_its_own_camera_and_mast_is_one_whole_candidate():
    img = np.full((140, 160, 3), GREY, np.uint8)
    landmark(img, 50, 20, 12, 28)  # 32-row white body from row 32, blue band rows 64-76
    img[40:58, 58:72] = (40, 70, 40)  # a dark green camera box in front of the white body
    img[58:100, 63:67] = (30, 30, 30)  # its mast, through the blue band: the blue region falls in two
    (c,) = search(img)
    assert c.red_bbox_px[0] == 50 and c.red_bbox_px[2] == 28 and c.white_px == 32
    assert c.visible == pytest.approx(1.0)


def test_a_dark_chassis_between_a_red_box_and_a_blue_mat_is_no_white_body():
    img = np.full((120, 160, 3), GREY, np.uint8)
    img[20:30, 50:71] = RED  # a red box's lower edge ...
    img[30:54, 50:71] = (50, 50, 50)  # ... a dark robot chassis (grey enough for the white class) ...
    img[54:64, 50:71] = BLUE  # ... and a blue mat: the shape of a landmark, but no white body
    assert search(img) == []


def test_a_search_explains_its_regions_only_when_every_one_is_a_found_landmarks_band():
    from rangebearing.core.structure import search as structure_search

    def found(img):
        hsv = to_hsv(img)
        red = ((hsv[..., 0] < 10) & (hsv[..., 1] > 90)).astype(np.uint8) * 255
        blue = ((hsv[..., 0] > 98) & (hsv[..., 0] < 132) & (hsv[..., 1] > 90)).astype(np.uint8) * 255
        return structure_search(red, blue, hsv, 1, GEOMETRY, 16)

    img = np.full((120, 160, 3), GREY, np.uint8)
    landmark(img, 50, 20, 9, 21)
    f = found(img)
    assert len(f.candidates) == 1 and f.explained()
    img[90:100, 120:140] = RED  # a red box the landmark does not explain
    f = found(img)
    assert len(f.candidates) == 1 and not f.explained()
    img = np.full((120, 160, 3), GREY, np.uint8)
    img[20:29, 50:71] = RED  # a red band with no white body under these gains: a band, no landmark
    img[53:62, 50:71] = BLUE
    f = found(img)
    assert f.candidates == [] and not f.explained()
