"""A clipped band's hue: further from its primary than the paint's, and read so only where it is clipped."""

import numpy as np
import pytest

from rangebearing.core.color import (
    CLIPPED_HUE_REACH,
    class_hues,
    class_masks,
    clip_of,
    clipped_hue_tables,
    clipped_mask,
    clipped_v,
    to_hsv,
)

RED_HUE = ((0, 10), (165, 179))
BLUE_HUE = ((98, 132),)


def patch(bgr):
    return np.full((4, 4, 3), bgr, np.uint8)


def classes(bgr, clipped=None):
    red, blue = class_masks(to_hsv(patch(bgr)), RED_HUE, BLUE_HUE, 90, 25, clipped)
    return bool((red == 255).all()), bool((blue == 255).all())


@pytest.mark.parametrize(
    "clipped_bgr, unclipped_bgr, red, blue",
    [
        ((255, 230, 120), (240, 216, 113), False, True),  # blue band 1-2 stops over: hue 96 (cyan-ish)
        ((90, 160, 255), (85, 150, 240), True, False),  # red band clipped, its green lifted: hue 13 (orange-ish)
        ((208, 80, 255), (196, 75, 240), True, False),  # red band clipped leaning magenta: hue 158
        ((255, 80, 202), (240, 75, 190), False, True),  # blue band clipped leaning violet: hue 141
    ],
)
def test_a_clipped_band_keeps_its_class_where_the_same_hue_unclipped_has_none(clipped_bgr, unclipped_bgr, red, blue):
    assert classes(clipped_bgr) == (red, blue)
    assert classes(unclipped_bgr) == (False, False)


def test_a_band_clipped_before_the_gains_reads_the_wider_hues_too():
    band = patch((90, 160, 255))  # an orange-read red band, clipped; the gains pull red under 250 (hue 15)
    hsv = to_hsv((band * np.array([1.0, 1.0, 0.9])).astype(np.uint8))
    red, _ = class_masks(hsv, RED_HUE, BLUE_HUE, 90, 25)
    assert not red.any()
    red, _ = class_masks(hsv, RED_HUE, BLUE_HUE, 90, 25, clipped_mask(band))
    assert (red == 255).all()


@pytest.mark.parametrize("bgr", [(200, 220, 255), (255, 240, 190), (215, 225, 255)])
def test_a_white_bodys_tinted_highlight_stays_out_of_the_classes(bgr):
    # a clipped white body under a warm or a cool light: as pale as the body the column scan calls white
    assert classes(bgr) == (False, False)
    hsv = to_hsv(patch(bgr))
    assert not clip_of(hsv[..., 1], clipped_v(hsv[..., 2])).any()


def test_the_wider_ranges_never_meet_nor_take_the_other_class():
    red, blue = (t[:180, 0] > 0 for t in clipped_hue_tables(RED_HUE, BLUE_HUE))
    hue = np.arange(180)
    in_red = ((hue <= 10) | (hue >= 165))
    in_blue = (hue >= 98) & (hue <= 132)
    assert not (red & blue).any()
    assert not (red & in_blue).any() and not (blue & in_red).any()
    assert red.sum() == 26 + 2 * CLIPPED_HUE_REACH  # 0-10 and 165-179, 15 more on each side
    assert blue.sum() == 35 + 2 * CLIPPED_HUE_REACH
    # two ranges closer than twice the reach share the hues between them by nearness
    red2, blue2 = (t[:180, 0] > 0 for t in clipped_hue_tables(((0, 10), (165, 179)), ((130, 150),)))
    assert red2[158] and blue2[157] and not (red2 & blue2).any()


def test_without_clipped_pixels_the_hues_are_the_plain_ranges():
    h = np.arange(180, dtype=np.uint8).reshape(1, -1)
    none = np.zeros_like(h)
    for clip in (None, none):
        red, blue = class_hues(h, RED_HUE, BLUE_HUE, clip)
        assert np.flatnonzero(red).tolist() == [*range(0, 11), *range(165, 180)]
        assert np.flatnonzero(blue).tolist() == list(range(98, 133))
