"""Colour thresholds from band pixels: hand-built HSV samples with known spans."""

import numpy as np
import pytest

from rangebearing.core.color import hue_in
from rangebearing.core.colour_tune import Margins, band_core, derive_ranges, search_ladder, widen
from rangebearing.errors import CalibrationError


def pixels(hues, s=200, v=150):
    h = np.repeat(np.asarray(list(hues), np.uint8), 5)  # five pixels of each hue
    return np.column_stack([h, np.full_like(h, s), np.full_like(h, v)])


def accepts(ranges, hues):
    return hue_in(np.asarray(hues, np.uint8).reshape(-1, 1), ranges).ravel() == 255


def test_red_around_zero_wraps_into_two_ranges():
    red = pixels(list(range(175, 180)) + list(range(5)))  # 175..179, 0..4
    blue = pixels(range(110, 121))
    r = derive_ranges(red, blue, Margins(hue=6))
    # shifted by 90 the red spans 85..94, narrower than the minimum ±5 about its median 89.5:
    # 84.5..94.5 rounded out to 84..95, ±6 → 78..101, shifted back −12..11
    assert r.red_hue == ((0, 11), (168, 179))
    assert r.blue_hue == ((104, 126),)
    assert accepts(r.red_hue, red[:, 0]).all()
    assert not accepts(r.red_hue, blue[:, 0]).any()


def test_orange_red_gives_one_range_off_zero():
    r = derive_ranges(pixels(range(8, 17)), pixels(range(100, 111)), Margins(hue=4))
    # 8..16 → 98..106 shifted, median 102 ± 5 → 97..107, ±4 → 93..111 → 3..21
    assert r.red_hue == ((3, 21),)
    assert r.blue_hue == ((96, 114),)


def test_saturation_and_value_minimums_follow_the_dimmest_pixels():
    red = pixels([2] * 100, s=200, v=180)
    blue = np.vstack([pixels([115] * 90, s=220, v=160), pixels([115] * 10, s=140, v=60)])
    r = derive_ranges(red, blue, Margins(s_frac=0.6, v_frac=0.5))
    # a tenth of the blue pixels are dim: the 5th percentile is theirs (S 140, V 60)
    assert r.s_min == int(140 * 0.6)
    assert r.v_min == int(60 * 0.5)


def test_a_grey_band_is_refused():
    with pytest.raises(CalibrationError, match="barely saturated"):
        derive_ranges(pixels([2] * 50, s=40), pixels([115] * 50))


def test_too_few_pixels_are_refused():
    with pytest.raises(CalibrationError, match="only 5 red"):
        derive_ranges(pixels([2]), pixels([115] * 50))


def test_overlapping_bands_are_refused():
    with pytest.raises(CalibrationError, match="overlap"):
        derive_ranges(pixels(range(100, 110)), pixels(range(104, 114)))


def test_band_core_takes_the_middle_of_the_box():
    hsv = np.zeros((20, 30, 3), np.uint8)
    hsv[5:15, 10:20] = 7
    core = band_core(hsv, (14.5, 9.5), 10, 10, core=0.6)
    assert (core == 7).all()
    assert len(core) == 7 * 7  # ±3 px around the centre, rounded out to whole pixels


def test_widen_wraps_and_the_ladder_starts_with_the_current_thresholds():
    assert widen(((0, 10), (165, 179)), 6) == ((0, 16), (174, 179), (159, 179), (0, 5))
    ladder = search_ladder(((0, 10),), ((98, 132),), 90, 25)
    assert ladder[0] == (((0, 10),), ((98, 132),), 90, 25)
    assert ladder[-1][2] < 90 and ladder[-1][3] < 25


def test_the_second_looks_hues_reach_further_on_both_sides_of_each_class():
    from rangebearing.core.colour_tune import RELAXED_HUE, relaxed_hues
    from rangebearing.core.params import DetectionParams

    cfg = DetectionParams(red_hue=((0, 10), (165, 179)), blue_hue=((98, 132),))
    relaxed = relaxed_hues(cfg)
    h = np.arange(180, dtype=np.uint8).reshape(1, -1)
    red, blue = (np.flatnonzero(hue_in(h, r)).tolist() for r in (relaxed.red_hue, relaxed.blue_hue))
    assert red == [*range(0, 11 + RELAXED_HUE), *range(165 - RELAXED_HUE, 180)]  # magenta and orange paint
    assert blue == list(range(98 - RELAXED_HUE, 133 + RELAXED_HUE))  # cyan and violet paint
    assert not set(red) & set(blue)
    assert (relaxed.s_min, relaxed.v_min) == (cfg.s_min, cfg.v_min)  # the floors are relaxed_floors' business
