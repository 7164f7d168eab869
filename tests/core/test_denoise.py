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
