"""Pixels a white-balance gain pushes to 255 are classed by their colour before the saturation (core/gain_clip.py)."""

import numpy as np

from rangebearing.core.color import apply_gains, class_masks, clipped_mask, to_hsv
from rangebearing.core.gain_clip import pushed_over, unsaturated_hs
from rangebearing.core.params import DetectionParams
from rangebearing.core.search_image import SearchImage

CFG = DetectionParams()
BLUE_GAIN = (1.15, 0.97, 0.9)  # grey-world under a warm cast: blue up, red down
RED_GAIN = (0.95, 1.0, 1.1)


def _patch(bgr):
    return np.full((6, 8, 3), bgr, np.uint8)


def test_a_bright_white_body_under_a_blue_gain_is_no_blue_band():
    body = _patch((237, 234, 227))  # unclipped; the blue gain takes B to 272 -> 255
    hsv = to_hsv(apply_gains(body, BLUE_GAIN))
    _, saturated_blue = class_masks(hsv, CFG.red_hue, CFG.blue_hue, CFG.s_min, CFG.v_min, clipped_mask(body))
    assert saturated_blue.all()  # read as clipped, at half the saturation floor: the whole body was blue
    red, blue = SearchImage(body, BLUE_GAIN).class_masks(CFG, CFG.s_min, CFG.v_min)
    assert not blue.any() and not red.any()


def test_a_washed_out_band_keeps_its_saturation_before_the_gain():
    band = _patch((170, 170, 245))  # a red band under a filmic shoulder: S 78, under the floor as it is
    hue, sat = unsaturated_hs(band.reshape(-1, 3)[:1], RED_GAIN)
    assert abs(int(sat[0, 0]) - 102) <= 1 and int(hue[0, 0]) <= 3  # balanced (269, 170, 162) RGB
    red, blue = SearchImage(band, RED_GAIN).class_masks(CFG, CFG.s_min, CFG.v_min)
    assert red.all() and not blue.any()


def test_a_pixel_clipped_before_the_gains_keeps_the_clipped_rules():
    band = _patch((200, 205, 255))  # a red band in a spotlight: the sensor clipped red (S 55)
    assert pushed_over(band, BLUE_GAIN, to_hsv(apply_gains(band, BLUE_GAIN))[..., 2]) is None
    red, _ = SearchImage(band, RED_GAIN).class_masks(CFG, CFG.s_min, CFG.v_min)
    assert red.all()


def test_no_gain_above_one_pushes_nothing():
    body = _patch((240, 240, 240))
    assert pushed_over(body, (0.9, 1.0, 1.0), to_hsv(body)[..., 2]) is None
