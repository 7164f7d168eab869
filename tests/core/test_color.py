import numpy as np
import pytest

from rangebearing.core.color import apply_gains, class_masks, clipped_mask, grey_world_gains, hue_mask, to_hsv

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


def split_frame(top_bgr, bottom_bgr, bottom_share):
    """A 40×40 frame: ``top_bgr`` above, ``bottom_bgr`` filling the bottom ``bottom_share`` of the rows."""
    img = np.full((40, 40, 3), top_bgr, np.uint8)
    img[40 - round(40 * bottom_share) :] = bottom_bgr
    return img


@pytest.mark.parametrize(
    "surface",
    [
        (90, 30, 20),  # a navy carpet (BGR) over most of the frame
        (25, 30, 170),  # a red wall
        (40, 150, 40),  # a green floor
    ],
)
def test_a_large_coloured_surface_does_not_shift_the_balance(surface):
    warm_white = (150, 175, 200)  # the white body and walls under a warm cast
    gains = grey_world_gains(split_frame(warm_white, surface, 0.7))
    b, g, r = apply_gains(patch(warm_white), gains)[0, 0].astype(int)
    assert max(b, g, r) - min(b, g, r) <= 4  # the neutral surfaces come out neutral


def test_dark_and_clipped_pixels_do_not_vote():
    frame = split_frame((120, 120, 120), (8, 2, 12), 0.5)  # half the frame nearly black, faintly tinted
    frame[:10] = (255, 255, 230)  # a blown-out window
    assert grey_world_gains(frame) == pytest.approx((1.0, 1.0, 1.0), abs=0.01)


def test_a_clipped_highlight_on_a_band_keeps_its_class():
    hsv = to_hsv(patch((190, 200, 255)))  # a red band in a spotlight: red clipped, saturation ~0.25
    assert (hue_mask(hsv, RED_HUE, 90, 25) == 255).all()
    assert not (hue_mask(to_hsv(patch((190, 200, 240))), RED_HUE, 90, 25) == 255).any()  # unclipped: too pale


def test_a_band_clipped_before_the_gains_stays_clipped():
    # a red band in a spotlight (red clipped) in a frame balanced towards blue: the red gain
    # pulls 252 to 224, under the clipped threshold, but the pixel is still clipped
    band = patch((150, 160, 252))
    gains = (1.117, 1.022, 0.887)
    hsv = to_hsv(apply_gains(band, gains))
    red, _ = class_masks(hsv, RED_HUE, BLUE_HUE, 90, 25)
    assert not red.any()  # judged on the balanced pixel alone it is too pale
    red, _ = class_masks(hsv, RED_HUE, BLUE_HUE, 90, 25, clipped_mask(band))
    assert (red == 255).all()


def test_only_pixels_with_a_channel_at_250_or_more_are_clipped():
    frame = np.array([[(150, 160, 252), (249, 249, 249), (250, 10, 10), (0, 0, 0)]], np.uint8)
    assert clipped_mask(frame).tolist() == [[255, 0, 255, 0]]


@pytest.mark.parametrize("gains", [(1.0, 1.0, 1.0), (1.3, 1.0, 0.8), (0.7, 1.0, 1.4)])
def test_search_image_class_masks_are_color_class_masks(gains):
    from rangebearing.core.colour_tune import relaxed_hues
    from rangebearing.core.gain_clip import pushed_over, reclass_pushed
    from rangebearing.core.params import DetectionParams
    from rangebearing.core.search_image import SearchImage

    rng = np.random.default_rng(7)
    small = rng.integers(0, 256, (40, 60, 3), dtype=np.uint8)
    small[:5] = 255  # clipped rows
    cfg = DetectionParams()
    img = SearchImage(small, gains)
    hsv = to_hsv(apply_gains(small, gains))
    clip = clipped_mask(small) if min(gains) < 0.98 else None
    assert np.array_equal(img.hsv, hsv)
    wide = relaxed_hues(cfg)  # the second look's hue ranges: other hue masks from the same clipped pixels
    for c, s_min, v_min in ((cfg, cfg.s_min, cfg.v_min), (cfg, 60, 30), (wide, 60, 30), (cfg, cfg.s_min, cfg.v_min)):
        got = img.class_masks(c, s_min, v_min)  # the last again: the cached views
        want = class_masks(hsv, c.red_hue, c.blue_hue, s_min, v_min, clip)
        # and the pixels a gain above one pushed to 255 classed by their colour before it (core/gain_clip.py)
        want = reclass_pushed(*want, small, gains, pushed_over(small, gains, hsv[..., 2]), c.red_hue, c.blue_hue,
                              s_min)
        assert all(np.array_equal(g, w) for g, w in zip(got, want))
