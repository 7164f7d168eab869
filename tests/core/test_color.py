import numpy as np
import pytest

from rangebearing.core.color import apply_gains, grey_world_gains, hue_mask, soft_weights, to_hsv

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


def test_soft_weights_ramp_and_hue_gate():
    hsv = np.zeros((1, 4, 3), np.uint8)
    hsv[0, :, 0] = (0, 0, 0, 60)  # last pixel green hue
    hsv[0, :, 1] = (40, 90, 200, 255)
    hsv[0, :, 2] = 200
    w_x, w_y = soft_weights(hsv, RED_HUE, 90, 25, ramp=40)
    assert w_x.dtype == np.float32 and w_y.dtype == np.float32
    assert w_x[0, 0] == 0.0
    assert w_x[0, 1] == pytest.approx(0.5)
    assert w_x[0, 2] == 1.0
    assert w_x[0, 3] == 0.0 and w_y[0, 3] == 0.0


def test_vertical_weights_count_half_blends_the_same_against_white_and_black():
    red, white, black = np.array([40, 40, 200.0]), np.array([220, 220, 220.0]), np.array([15, 15, 15.0])
    column = [white, (red + white) / 2, red, red, red, (red + black) / 2, black]
    bgr = np.array(column, np.float64).round().astype(np.uint8).reshape(-1, 1, 3)
    _, w_y = soft_weights(to_hsv(bgr), RED_HUE, 90, 25)
    w = w_y[:, 0]
    assert w[0] == 0.0 and w[6] == 0.0
    assert w[1] == pytest.approx(w[5], abs=0.03)  # symmetric, so the centroid stays at the band centre
    ys = np.arange(len(w))
    assert (w * ys).sum() / w.sum() == pytest.approx(3.0, abs=0.02)
