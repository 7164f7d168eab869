import cv2
import numpy as np
import pytest

from rangebearing.core.denoise import (
    band_masks,
    band_preserving_ksize,
    blanked,
    both_outside,
    majority_filter,
    median_filter,
    none_apart_filtered,
    regrow,
)


@pytest.mark.parametrize("k", [3, 5, 7, 15])
def test_majority_equals_median_on_binary_masks_away_from_borders(k):
    rng = np.random.default_rng(k)
    mask = ((rng.random((60, 80)) < 0.45) * 255).astype(np.uint8)
    got = majority_filter(mask, k)
    want = cv2.medianBlur(mask, k)
    m = k // 2
    assert np.array_equal(got[m:-m, m:-m], want[m:-m, m:-m])


def test_majority_removes_isolated_pixels_and_keeps_solid_regions():
    mask = np.zeros((20, 20), np.uint8)
    mask[5, 5] = 255  # salt
    mask[10:16, 4:16] = 255  # a solid band 6 px tall
    out = majority_filter(mask, 5)
    assert out[5, 5] == 0
    assert out[12, 10] == 255 and out[13, 10] == 255


def test_ksize_one_is_identity():
    mask = np.eye(5, dtype=np.uint8) * 255
    assert majority_filter(mask, 1) is mask
    img = np.zeros((5, 5, 3), np.uint8)
    assert median_filter(img, 1) is img


@pytest.mark.parametrize("band_px, expected", [(10.0, 15), (5.0, 9), (2.4, 3), (1.0, 1), (8.0, 15)])
def test_band_preserving_ksize(band_px, expected):
    assert band_preserving_ksize(15, band_px) == expected


@pytest.mark.parametrize("h", [2, 3, 5, 8])
def test_band_preserving_ksize_really_keeps_the_band(h):
    k = band_preserving_ksize(15, h)
    mask = np.zeros((40, 60), np.uint8)
    mask[20 : 20 + h, 5:55] = 255
    assert majority_filter(mask, k)[20 + h // 2, 30] == 255
    too_big = k + 2
    if too_big <= 15 and too_big >= 2 * h + 1:
        assert majority_filter(mask, too_big)[20 + h // 2, 30] == 0


def test_paper_median_15_erases_a_five_pixel_band():
    img = np.full((60, 80, 3), 200, np.uint8)
    img[30:35, 10:70] = (40, 40, 180)
    assert (median_filter(img, 15)[32, 40] == 200).all()


def test_regrow_gives_a_thin_band_its_ends_back_and_leaves_specks_removed():
    raw = np.zeros((12, 20), np.uint8)
    raw[5:7, 4:9] = 255  # a 2-row band 5 columns wide (a landmark at 2 m, half resolution)
    raw[1, 15] = 255  # salt
    filtered = majority_filter(raw, 3)
    assert np.count_nonzero(filtered[5:7]) == 6  # the vote ate a column at each end
    out = regrow(filtered, raw, 3)
    assert np.array_equal(out[5:7, 4:9], raw[5:7, 4:9]) and np.count_nonzero(out) == 10
    red, blue = band_masks(raw, np.zeros_like(raw), 3)
    assert np.array_equal(red, out) and not blue.any()
    assert regrow(filtered, raw, 1) is filtered


def test_regrow_keeps_what_the_filter_filled_in():
    raw = np.full((9, 9), 255, np.uint8)
    raw[4, 4] = 0  # pepper inside a solid region
    out = regrow(majority_filter(raw, 3), raw, 3)
    assert out[4, 4] == 255


def test_blanked_clears_each_box_grown_by_one_mask_pixel_and_nothing_else():
    mask = np.full((20, 30), 255, np.uint8)
    out = blanked(mask, [(10, 8, 15, 13)], 2)  # full-res columns 10-14, rows 8-12 -> mask cols 5-7, rows 4-6
    assert (out[3:8, 4:9] == 0).all()  # grown by one: rows 3-7, cols 4-8
    assert np.count_nonzero(out == 0) == 5 * 5
    assert (mask == 255).all() and blanked(mask, [], 2) is mask  # the input is never changed


def test_both_outside_needs_red_and_blue_beyond_every_box():
    red, blue = np.zeros((20, 30), np.uint8), np.zeros((20, 30), np.uint8)
    red[5, 6], blue[9, 6] = 255, 255  # a landmark's bands, inside the box below
    box = [(10, 8, 15, 20)]  # full-res columns 10-14, rows 8-19
    assert not both_outside(red, blue, box, 2)
    red[5, 20] = 255
    assert not both_outside(red, blue, box, 2)  # red beyond it, but no blue
    blue[12, 25] = 255
    assert both_outside(red, blue, box, 2) and both_outside(red, blue, [], 2)


@pytest.mark.parametrize("k", [3, 5, 7])
def test_none_apart_filtered_is_never_wrong_about_the_filtered_masks(k):
    # dense blobs inside boxes and, sometimes, specks or blobs outside: whenever the raw masks say
    # "nothing apart", the filtered masks must say so too (the second look then skips its filter)
    rng = np.random.default_rng(100 + k)
    said = 0
    for trial in range(300):
        red = np.zeros((60, 80), np.uint8)
        blue = np.zeros_like(red)
        n = int(rng.integers(1, 4))
        boxes = []
        for _ in range(n):
            x0, y0 = int(rng.integers(0, 140)), int(rng.integers(0, 100))
            boxes.append((x0, y0, x0 + int(rng.integers(4, 30)), y0 + int(rng.integers(4, 30))))
        for mask in (red, blue):
            for x0, y0, x1, y1 in boxes:  # fill each box (mask pixels, as blanked() clears them) densely
                r0, r1, c0, c1 = max(0, y0 // 2 - 1), -(-y1 // 2) + 1, max(0, x0 // 2 - 1), -(-x1 // 2) + 1
                mask[r0:r1, c0:c1] = (rng.random(mask[r0:r1, c0:c1].shape) < 0.9) * 255
            if trial % 3 == 0:
                mask[int(rng.integers(0, 60)), int(rng.integers(0, 80))] = 255
        if none_apart_filtered(red, blue, boxes, 2, k):
            said += 1
            assert not both_outside(*band_masks(red, blue, k), boxes, 2)
    assert said > 50  # the gate does say so, often


def test_none_apart_filtered_filters_when_two_boxes_are_within_one_window():
    # two dense boxes one mask column apart: the majority window fills the column between them
    red = np.zeros((20, 40), np.uint8)
    red[4:12, 4:10] = 255
    red[4:12, 11:17] = 255
    boxes = [(10, 10, 18, 22), (24, 10, 32, 22)]  # mask columns 4-9 and 11-16 once grown by one
    assert not both_outside(red, red, boxes, 2)  # the raw masks hold nothing outside the boxes ...
    assert both_outside(*band_masks(red, red, 3), boxes, 2)  # ... the filtered ones do: column 10
    assert not none_apart_filtered(red, red, boxes, 2, 3)  # too close to judge on the raw masks
    far = [(10, 10, 18, 22), (40, 10, 48, 22)]
    assert none_apart_filtered(np.zeros_like(red), red, far, 2, 3)
