"""Camera presets against the published Raspberry Pi figures, worked out by hand."""

import math

import pytest

from rangebearing.core.camera_models import PRESETS, default_crop, preset_intrinsics


def test_pi_v2_published_focal_length_in_pixels():
    # 3.04 mm / 1.12 µm = 2714.3 px at the full 3280-pixel width
    full = preset_intrinsics("pi-v2", 3280, 2464)
    assert full.fx_px == pytest.approx(2714.29, abs=0.01)
    assert full.fy_px == pytest.approx(2714.29, abs=0.01)
    assert (full.cx_px, full.cy_px) == (1639.5, 1231.5)
    vga = preset_intrinsics("pi-v2", 640, 480)  # the whole array scaled down: ×640/3280
    assert vga.fx_px == pytest.approx(2714.29 * 640 / 3280, abs=0.01)  # 529.6 px
    assert (vga.cx_px, vga.cy_px) == pytest.approx((319.5, 239.5))


def test_pi_v1_matches_the_documented_634_px():
    cam = preset_intrinsics("pi-v1", 640, 480)  # 3.60 mm / 1.4 µm · 640/2592
    assert cam.fx_px == pytest.approx(634.9, abs=0.1)


@pytest.mark.parametrize(("model", "tol_deg"), [("pi-v1", 0.15), ("pi-v2", 0.15), ("pi-v3", 3.0)])
def test_horizontal_fov_matches_the_published_figure(model, tol_deg):
    p = PRESETS[model]
    cam = preset_intrinsics(model, p.array_w_px, p.array_h_px)
    assert math.degrees(cam.hfov_rad) == pytest.approx(p.hfov_deg_published, abs=tol_deg)


def test_16_by_9_sensor_at_4_by_3_output_crops_the_sides():
    # IMX708 4608×2592 → 640×480: the centred 3456×2592 window, f = 4.74/1.4e-3 · 640/3456
    assert default_crop(PRESETS["pi-v3"], 640, 480) == (576, 0, 3456, 2592)
    cam = preset_intrinsics("pi-v3", 640, 480)
    assert cam.fx_px == pytest.approx(3385.71 * 640 / 3456, abs=0.01)
    assert cam.fx_px == pytest.approx(cam.fy_px)
    assert cam.cx_px == pytest.approx(319.5)


def test_cropped_sensor_mode_doubles_the_focal_length():
    # IMX219's 640×480 mode reads the centred 1280×960 window (binned 2×2): half the field of view
    mode = (1000, 752, 1280, 960)
    cam = preset_intrinsics("pi-v2", 640, 480, mode_crop=mode)
    assert cam.fx_px == pytest.approx(2714.29 * 640 / 1280, abs=0.01)
    assert (cam.cx_px, cam.cy_px) == pytest.approx((319.5, 239.5))


def test_off_centre_scaler_crop_moves_the_principal_point():
    # a 1640×1232 window whose left edge is at x=0: the array's centre column 1639.5 lands at
    # (1639.5 + 0.5 − 0)·640/1640 − 0.5 = 639.5, the right edge of the frame
    cam = preset_intrinsics("pi-v2", 640, 480, scaler_crop=(0, 616, 1640, 1232))
    assert cam.cx_px == pytest.approx(639.5)
    assert cam.cy_px == pytest.approx((1231.5 + 0.5 - 616) * 480 / 1232 - 0.5)


def test_crop_outside_the_array_is_refused():
    with pytest.raises(ValueError, match="not inside"):
        preset_intrinsics("pi-v2", 640, 480, scaler_crop=(3000, 0, 1280, 960))
