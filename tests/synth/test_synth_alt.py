"""Another camera and paint (photoreal-alt): tone curves, pan blur, barrel, video coding, paint hues."""

from __future__ import annotations

import colorsys
import dataclasses

import numpy as np
import pytest

from rangebearing.core.types import CameraIntrinsics
from rangebearing.errors import SceneError
from rangebearing.synth import Imaging, LandmarkPose, Lighting, Scene, isp, optics, random_scene, render
from rangebearing.synth.photoreal_alt import ALT_PRESET, turned
from rangebearing.synth.scene import BLUE_PAINT, RED_PAINT

TINY = CameraIntrinsics().scaled(160, 120)


def test_srgb_curve_is_the_standard_one():
    lut = isp.tone_lut("srgb")
    for x, want in ((0.0, 0), (0.002, 0.002 * 12.92), (0.18, 1.055 * 0.18 ** (1 / 2.4) - 0.055), (1.0, 1.0)):
        assert lut[round(x * 65535)] == round(255 * want)


def test_filmic_curve_darkens_shadows_brightens_highlights_and_keeps_mid_grey():
    srgb, film = isp.tone_lut("srgb").astype(int), isp.tone_lut("filmic").astype(int)
    assert np.all(np.diff(film) >= 0) and film[0] == 0 and film[-1] == 255
    mid = int(np.searchsorted(srgb, 128))  # the linear code sRGB puts at half scale
    assert abs(film[mid] - 128) <= 1
    quarter, three = int(np.searchsorted(srgb, 64)), int(np.searchsorted(srgb, 192))
    assert film[quarter] < 64 - 10 and film[three] > 192 + 10
    with pytest.raises(ValueError):
        isp.tone_lut("log")


@pytest.mark.parametrize("length", (2.5, 6.0))
def test_pan_blur_spreads_a_bar_by_its_length_and_keeps_its_centre(length):
    k = optics.box_kernel(length)
    assert k.sum() == pytest.approx(1.0, abs=1e-6) and np.allclose(k, k[::-1])
    img = np.zeros((5, 41, 3), np.float32)
    img[:, 20] = 1.0
    row = optics.pan_blur(img, length)[2, :, 0]
    x = np.arange(41)
    assert (row * x).sum() / row.sum() == pytest.approx(20.0, abs=1e-5)
    assert np.count_nonzero(row > 1e-6) <= length + 2  # a box of that length (fractional ends)
    assert row.max() == pytest.approx(1.0 / length, rel=1e-5) and row.sum() == pytest.approx(1.0, rel=1e-5)


def test_barrel_pulls_off_centre_points_inwards_by_k1_r_squared():
    cam = CameraIntrinsics()
    img = np.zeros((cam.height_px, cam.width_px, 3), np.float32)
    u, v = 600, 240  # x_n = 0.442, on the principal row
    img[v - 1 : v + 2, u - 1 : u + 2] = 1.0
    out = optics.barrel(img, -0.02, cam.fx_px, cam.fy_px, cam.cx_px, cam.cy_px)
    ys, xs = np.nonzero(out[..., 0] > 1e-3)
    w = out[ys, xs, 0]
    xn = (u - cam.cx_px) / cam.fx_px
    want = cam.cx_px + xn * (1 - 0.02 * xn * xn) * cam.fx_px
    assert (w * xs).sum() / w.sum() == pytest.approx(want, abs=0.1)
    assert np.array_equal(optics.barrel(img, 0.0, 1, 1, 0, 0), img)


def test_video_coding_keeps_colour_in_2x2_blocks():
    rng = np.random.default_rng(0)
    img = rng.integers(0, 256, (16, 16, 3)).astype(np.uint8)
    blocks = isp.subsample_chroma(img, blocks=True)
    import cv2

    cr = cv2.cvtColor(blocks, cv2.COLOR_BGR2YCrCb)[..., 1].astype(int)
    assert np.ptp(cr[0:2, 0:2]) <= 2  # one chroma sample per 2x2 (rounding through BGR aside)
    assert isp.h264(img, 50).shape == img.shape


def test_turned_paint_moves_the_display_hue_and_keeps_it_at_zero():
    assert turned(RED_PAINT, 0.0, 1.0, 1.0) == pytest.approx(RED_PAINT, abs=1e-9)

    def hue(c):
        return colorsys.rgb_to_hsv(*[x ** (1 / 2.2) for x in c])[0] * 360

    assert hue(turned(RED_PAINT, 12.0, 1.0, 1.0)) == pytest.approx(hue(RED_PAINT) + 12.0, abs=0.01)
    assert hue(turned(BLUE_PAINT, -20.0, 1.0, 1.0)) == pytest.approx(hue(BLUE_PAINT) - 20.0, abs=0.01)


def test_scene_paint_colours_the_landmark():
    flat = Lighting(ambient=1.0, exposure=1.0)
    base = Scene(camera=TINY, landmarks=(LandmarkPose(0.4, 0.0),), lighting=flat, wall_distance_m=None)
    green = ((0.1, 0.6, 0.1), (0.85, 0.85, 0.85), (0.6, 0.1, 0.6))
    a, b = render(base), render(dataclasses.replace(base, paint=green))
    assert not np.array_equal(a, b)
    assert np.array_equal(render(dataclasses.replace(base, paint=(RED_PAINT, (0.85,) * 3, BLUE_PAINT))), a)


def test_alt_preset_draws_other_cameras_deterministically():
    scenes = [random_scene(np.random.default_rng(40 + i), ALT_PRESET, TINY) for i in range(6)]
    assert all(s.paint is not None and s.imaging.isp and s.imaging.ccm for s in scenes)
    assert {s.imaging.tone for s in scenes} - {"gamma"}
    again = random_scene(np.random.default_rng(40), ALT_PRESET, TINY)
    assert again == scenes[0]
    img = render(scenes[0], np.random.default_rng(1))
    assert img.shape == (120, 160, 3) and np.array_equal(img, render(scenes[0], np.random.default_rng(1)))


def test_bad_alt_settings_are_named():
    with pytest.raises(SceneError, match="tone"):
        Scene(imaging=Imaging(tone="log"))
    with pytest.raises(SceneError, match="h264_quality"):
        Scene(imaging=Imaging(h264_quality=101))


def test_alt_preset_draws_pincushion_and_mjpeg_too():
    scenes = [random_scene(np.random.default_rng(100 + i), ALT_PRESET, TINY) for i in range(40)]
    k1 = [s.imaging.barrel_k1 for s in scenes]
    assert min(k1) < 0 < max(k1) <= 0.008 and min(k1) >= -0.012  # barrel and pincushion residuals
    assert any(40 <= s.imaging.jpeg_quality <= 75 for s in scenes)  # an MJPEG stream's coarse JPEG
