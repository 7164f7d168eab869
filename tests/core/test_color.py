import numpy as np
import pytest

from rangebearing.core.color import apply_gains, grey_world_gains, hue_mask, to_hsv

RED_HUE = ((0, 10), (165, 179))
BLUE_HUE = ((98, 132),)


def patch(bgr):
    return np.full((4, 4, 3), bgr, np.uint8)


@pytest.mark.parametrize(
    "bgr, red, blue",
    [
        ((30, 30, 200), True, False),  # red
        ((60, 20, 200), True, False),  # red leaning magenta: hue wraps near 179
        ((200, 40, 30), False, True),  # blue
        ((180, 180, 180), False, False),  # white
        ((40, 160, 40), False, False),  # green
        ((70, 110, 160), False, False),  # tan floor: orange-ish, low saturation
        ((5, 5, 20), False, False),  # too dark to trust
    ],
)
def test_hue_masks_classify_hand_picked_colours(bgr, red, blue):
    hsv = to_hsv(patch(bgr))
    assert (hue_mask(hsv, RED_HUE, 90, 25) == 255).all() == red
    assert (hue_mask(hsv, BLUE_HUE, 90, 25) == 255).all() == blue


def test_grey_world_neutral_frame_gives_unit_gains():
    g = grey_world_gains(patch((120, 120, 120)))
    assert g == pytest.approx((1.0, 1.0, 1.0))


def test_grey_world_undoes_a_warm_cast():
    warm = patch((90, 120, 150))  # blue low, red high
    gains = grey_world_gains(warm)
    balanced = apply_gains(warm, gains)
    b, g, r = balanced[0, 0].astype(int)
    assert abs(b - r) <= 2 and abs(g - r) <= 2


def test_grey_world_gains_are_clipped():
    gains = grey_world_gains(patch((2, 2, 250)), limit=2.0)
    assert min(gains) >= 0.5 and max(gains) <= 2.0
