"""The lens and ISP of the photoreal presets: defocus, colour matrix, AWB, sharpening, presets."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rangebearing.core.types import CameraIntrinsics
from rangebearing.errors import SceneError
from rangebearing.synth import Imaging, LandmarkPose, Lighting, Scene, isp, optics, random_scene, render
from rangebearing.synth.photoreal import PHOTOREAL_PRESETS, defocus_px
from rangebearing.synth.render import render_layers

SMALL = CameraIntrinsics().scaled(320, 240)
FLAT = Lighting(ambient=1.0, exposure=1.0)


def _red_rows(linear: np.ndarray, col: int) -> np.ndarray:
    """Redness (R − G) down one column of a linear image."""
    return linear[:, col, 0] - linear[:, col, 1]


def _steepest(profile: np.ndarray) -> float:
    """The largest row-to-row change of a band profile, relative to its peak."""
    return float(np.abs(np.diff(profile)).max() / profile.max())


def test_blur_disc_follows_the_thin_lens():
    c = optics.coc_px(np.array([0.2, 1.0, np.inf]), 1.0, 0.00124, 634.0)
    assert c[0] == pytest.approx(0.00124 * 634 * 4.0) and c[1] == 0.0
    assert c[2] == pytest.approx(0.00124 * 634)  # beyond focus: at most A·fx/z_f
    k = optics.disc(3.0)
    assert k.sum() == pytest.approx(1.0, abs=1e-6) and k.shape[0] % 2 == 1


@pytest.mark.parametrize("range_m", (0.2, 0.3))
def test_defocus_softens_a_near_band_and_keeps_its_centroid(range_m):
    cam = CameraIntrinsics()  # 640 px wide: blur discs of 3.6 and 2.2 px
    scene = Scene(camera=cam, landmarks=(LandmarkPose(range_m, 0.0),), lighting=FLAT)
    linear, depth = render_layers(scene)
    soft = optics.defocus(linear, depth, 2.0, 0.00124, cam.fx_px)
    col = int(cam.cx_px)
    sharp_p, soft_p = np.clip(_red_rows(linear, col), 0, None), np.clip(_red_rows(soft, col), 0, None)
    assert _steepest(soft_p) < 0.85 * _steepest(sharp_p)
    rows = np.arange(len(sharp_p))
    c0 = (rows * sharp_p).sum() / sharp_p.sum()
    c1 = (rows * soft_p).sum() / soft_p.sum()
    assert c1 == pytest.approx(c0, abs=0.1)  # a symmetric disc: the band does not move


def test_a_landmark_in_focus_stays_sharp_and_a_near_blur_does_not_cover_a_far_edge():
    far = LandmarkPose(1.0, 0.05)
    scene = Scene(camera=SMALL, landmarks=(far, LandmarkPose(0.2, -0.2)), lighting=FLAT)
    linear, depth = render_layers(scene)
    soft = optics.defocus(linear, depth, 1.0, 0.00124, SMALL.fx_px)
    u = int(SMALL.cx_px - SMALL.fx_px * np.tan(0.05))
    window = (slice(60, 140), slice(u - 12, u + 12))
    assert np.abs(soft[window] - linear[window]).max() < 0.02


def test_colour_matrix_keeps_grey_and_an_identity_isp_is_the_plain_sensor():
    ccm = tuple(float(v) for row in isp.OV5647_CCMS[1] for v in row)
    grey = np.full((2, 2, 3), 0.4, np.float32)
    raw = isp.to_sensor(grey, ccm)
    assert np.allclose(raw, 0.4, atol=1e-5) and np.allclose(isp.from_sensor(raw, ccm), 0.4, atol=1e-5)
    red = np.array([[[0.7, 0.07, 0.06]]], np.float32)
    assert np.ptp(isp.to_sensor(red, ccm)) < np.ptp(red)  # the sensor sees it desaturated
    base = Imaging(auto_exposure=True, bayer=True, read_noise=0.004, shot_noise=0.0008)
    scene = Scene(camera=SMALL, landmarks=(LandmarkPose(0.5, 0.1),), imaging=base)
    identity = dataclasses.replace(base, ccm=(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0))
    a = render(scene, np.random.default_rng(3))
    b = render(dataclasses.replace(scene, imaging=identity), np.random.default_rng(3))
    assert identity.isp and not base.isp
    assert np.array_equal(a, b)
    c = render(dataclasses.replace(scene, imaging=dataclasses.replace(base, ccm=ccm)),
               np.random.default_rng(3))
    wall = (slice(10, 40), slice(10, 60))  # flat wall: what varies is noise
    chroma = lambda im: np.std(im[wall].astype(float)[..., 2] - im[wall].astype(float)[..., 0])  # noqa: E731
    assert chroma(c) > 1.3 * chroma(a)


def test_awb_is_pulled_by_a_large_blue_area_and_not_by_grey():
    grey = np.full((64, 64, 3), 0.3, np.float32)
    assert isp.awb_gains(grey, (1.0, 1.0, 1.0), 0.4) == pytest.approx((1.0, 1.0, 1.0))
    navy = grey.copy()
    navy[32:] = (0.05, 0.07, 0.2)
    r, g, b = isp.awb_gains(navy, (1.0, 1.0, 1.0), 0.4)
    assert g == 1.0 and b < 0.9 and r > 1.01  # grey world: (0.185/0.25)^0.4 = 0.89
    assert isp.awb_gains(navy, (1.1, 1.0, 0.9), 0.0) == (1.1, 1.0, 0.9)


def test_sharpening_overshoots_a_step_edge():
    step = np.full((8, 40, 3), 60, np.uint8)
    step[:, 20:] = 160
    out = isp.sharpen(step, 1.0).astype(int)
    assert out[:, 20].min() > 170 and out[:, 19].max() < 50  # a light and a dark halo
    assert (out[:, 30] == 160).all() and (out[:, 8] == 60).all()  # flat: untouched


def test_chroma_420_and_jpeg_keep_the_frame_shape():
    img = np.zeros((24, 30, 3), np.uint8)
    img[:, ::2] = (0, 0, 200)  # red stripes one pixel wide
    sub = isp.subsample_chroma(img)
    assert sub.shape == img.shape and np.ptp(sub[..., 2].astype(int)) < np.ptp(img[..., 2].astype(int))
    assert isp.jpeg(img, 80).shape == img.shape


@pytest.mark.parametrize("preset", PHOTOREAL_PRESETS)
def test_photoreal_presets_run_the_lens_and_isp_and_are_deterministic(preset):
    rng = np.random.default_rng(31)
    scenes = [random_scene(rng, preset, SMALL) for _ in range(6)]
    assert all(s.imaging.isp and s.imaging.focus_m >= 0.8 and s.imaging.ccm for s in scenes)
    assert all(lm.body is not None for s in scenes for lm in s.landmarks)
    near = [lm.range_m for s in scenes for lm in s.landmarks if defocus_px(s, lm.range_m) > 1.5]
    assert all(r < 0.5 for r in near)
    again = random_scene(np.random.default_rng(31), preset, SMALL)
    assert again == scenes[0]
    a = render(scenes[0], np.random.default_rng(5))
    assert a.shape == (240, 320, 3) and np.array_equal(a, render(again, np.random.default_rng(5)))


def test_bad_isp_settings_are_named():
    with pytest.raises(SceneError, match="demosaic"):
        Scene(imaging=Imaging(demosaic="vng", jpeg_quality=120))
    with pytest.raises(SceneError) as err:
        Scene(imaging=Imaging(demosaic="vng", jpeg_quality=120, ccm=(1.0,)))
    assert len(err.value.problems) == 3
