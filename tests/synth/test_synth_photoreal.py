"""The lens and ISP of the photoreal presets: defocus, colour matrix, AWB, sharpening, presets."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rangebearing.core.types import CameraIntrinsics
from rangebearing.errors import SceneError
from rangebearing.synth import (
    Box,
    Imaging,
    LandmarkPose,
    Lighting,
    Scene,
    bounce,
    ground,
    isp,
    optics,
    random_scene,
    render,
    surfaces,
)
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
    scenes = [random_scene(rng, preset, SMALL) for _ in range(4)]
    assert all(s.imaging.isp and s.imaging.focus_m >= 0.8 and s.imaging.ccm for s in scenes)
    assert all(lm.body is not None for s in scenes for lm in s.landmarks)
    near = [lm.range_m for s in scenes for lm in s.landmarks if defocus_px(s, lm.range_m) > 1.5]
    assert all(r < 0.5 for r in near)
    again = random_scene(np.random.default_rng(31), preset, SMALL)
    assert again == scenes[0]
    assert all(s.floor_shading and s.local_bounce for s in scenes)
    tiny = CameraIntrinsics().scaled(160, 120)
    one = random_scene(np.random.default_rng(32), preset, tiny)
    a = render(one, np.random.default_rng(5))
    assert a.shape == (120, 160, 3) and np.array_equal(a, render(one, np.random.default_rng(5)))


def test_bad_isp_settings_are_named():
    with pytest.raises(SceneError, match="demosaic"):
        Scene(imaging=Imaging(demosaic="vng", jpeg_quality=120))
    with pytest.raises(SceneError) as err:
        Scene(imaging=Imaging(demosaic="vng", jpeg_quality=120, ccm=(1.0,)))
    assert len(err.value.problems) == 3


def _floor_row(scene: Scene, row: int) -> np.ndarray:
    return render_layers(scene, supersample=1)[0][row]


def test_an_object_shadows_the_floor_softly_and_darkens_its_base():
    light = Lighting(direction=(-1.0, 1.0, 0.0), ambient=0.4, gloss=0.01)  # from the left, 45 deg up
    box = Box(0.0, 0.5, 0.06, 0.06, 0.0, 0.06, (0.5, 0.5, 0.5))
    base = Scene(camera=SMALL, boxes=(box,), lighting=light, wall_distance_m=None)
    hard = dataclasses.replace(base, floor_shading=True)
    soft = dataclasses.replace(hard, lighting=dataclasses.replace(light, light_radius_deg=12.0))
    row = int(SMALL.cy_px + SMALL.fy_px * 0.1 / 0.47)  # the floor just in front of the box's base
    plain, h, s = (_floor_row(sc, row)[:, 1] for sc in (base, hard, soft))
    cx = int(SMALL.cx_px)
    right = slice(cx + 30, cx + 60)  # the shadow falls to the right (+X is right in the image)
    assert h[right].mean() < 0.75 * plain[right].mean()
    assert 0.9 * plain[cx - 60:cx - 40].mean() < h[cx - 60:cx - 40].mean() < plain[cx - 60:cx - 40].mean()  # AO only
    assert h[cx - 200:cx - 180].mean() == pytest.approx(plain[cx - 200:cx - 180].mean(), rel=5e-3)  # 0.3 m away
    ramp = lambda v: int(((v > 1.02 * v.min()) & (v < 0.98 * v.max())).sum())  # noqa: E731
    assert ramp(s[cx:cx + 150] / plain[cx:cx + 150]) > ramp(h[cx:cx + 150] / plain[cx:cx + 150]) + 3


def test_ambient_occlusion_is_strongest_at_an_objects_base():
    obj = ground.Standing(0.0, 1.0, 0.05, 0.05, (0.0, 0.0), np.ones((2, 2), np.float32))
    pts = np.array([[0.06, 0.0, 1.0], [0.15, 0.0, 1.0], [0.6, 0.0, 1.0], [0.0, 0.0, 1.0]])
    occ = ground._occlusion(obj, pts)
    assert occ[3] == 0.9 and 0.2 < occ[0] < 0.5 and occ[0] > occ[1] > occ[2] and occ[2] < 0.005


def _sides(scene: Scene) -> tuple:
    linear = render_layers(scene)[0]
    rows = slice(int(SMALL.cy_px) - 4, int(SMALL.cy_px) + 4)  # white body, camera height
    u = int(SMALL.cx_px)
    left, right = linear[rows, u - 10:u - 7].mean(axis=(0, 1)), linear[rows, u + 7:u + 10].mean(axis=(0, 1))
    return left, right


def test_a_red_box_beside_a_landmark_tints_the_white_side_facing_it():
    light = Lighting(ambient=0.6, direction=(0.0, 1.0, -0.2), gloss=0.01)
    red = Box(-0.045, 0.5, 0.04, 0.06, 0.0, 0.2, (0.7, 0.05, 0.05))  # left of the landmark
    scene = Scene(camera=SMALL, landmarks=(LandmarkPose(0.5, 0.0),), boxes=(red,), lighting=light)
    left, right = _sides(dataclasses.replace(scene, local_bounce=True))
    ref_l, ref_r = _sides(scene)
    assert ref_l[0] / ref_l[1] == pytest.approx(ref_r[0] / ref_r[1], rel=0.01)
    assert left[0] / left[1] > 1.05 * right[0] / right[1]  # pink on the box's side
    assert left[1] < ref_l[1]  # less green light from there


def test_a_dark_board_under_a_landmark_darkens_its_blue_band_more_than_its_red_band():
    from rangebearing.synth.robots import zumo
    lm = LandmarkPose(0.5, 0.0, body=zumo(np.random.default_rng(1)), heading_rad=1.0)
    light = Lighting(ambient=0.8, direction=(0.0, 1.0, -0.3), gloss=0.01)
    scene = Scene(camera=SMALL, landmarks=(lm,), lighting=light)
    plain, near = render_layers(scene)[0], render_layers(dataclasses.replace(scene, local_bounce=True))[0]
    u, f = int(SMALL.cx_px), SMALL.fy_px
    blue = int(SMALL.cy_px + f * (0.1 - 0.0725) / 0.4825)
    red = int(SMALL.cy_px - f * (0.1275 - 0.1) / 0.4825)
    drop = lambda r: near[r, u].sum() / plain[r, u].sum()  # noqa: E731
    assert drop(blue) < 0.97 and drop(blue) < drop(red) - 0.02


def test_fresnel_mirrors_the_room_at_the_silhouette_only():
    n = np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])
    v = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, -1.0]])
    r = bounce.fresnel(n, v)
    assert r[0] == pytest.approx(0.04) and r[1] == pytest.approx(1.0)


def test_seams_and_grout_are_anti_aliased_and_patterns_vary():
    pos = np.linspace(0.0, 10.0, 20001)
    cover = surfaces._line_cover(pos, 0.1, 0.002, np.full(pos.shape, 0.05))
    assert cover.mean() == pytest.approx(0.02, rel=0.05) and cover.max() < 0.1  # footprint ≫ seam
    sharp = surfaces._line_cover(pos, 0.1, 0.002, np.full(pos.shape, 1e-4))
    assert sharp.max() == 1.0 and sharp.mean() == pytest.approx(0.02, rel=0.05)
    rng = np.random.default_rng(4)
    x, z = rng.uniform(-1, 1, 4000), rng.uniform(0.2, 2, 4000)
    foot = np.full(x.shape, 5e-4)
    for kind in surfaces.PATTERNS:
        g = surfaces.floor_gain(x, z, foot, foot, kind, surfaces.params(rng, kind), 3)
        assert g.shape == (4000, 3) and 0.05 < g[:, 1].std() < 0.5 and g.min() > 0.0


def test_a_moving_landmark_blurs_about_its_mid_exposure_pose():
    from rangebearing.synth.render import motion_steps
    lm = LandmarkPose(0.4, 0.0, velocity_mps=(0.3, 0.0))  # crossing to the right at 0.3 m/s
    still = Scene(camera=SMALL, landmarks=(dataclasses.replace(lm, velocity_mps=(0.0, 0.0)),), lighting=FLAT,
                  imaging=Imaging(exposure_s=0.03))
    moving = dataclasses.replace(still, landmarks=(lm,))
    assert motion_steps(still) == 1 and motion_steps(moving) % 2 == 1 and motion_steps(moving) >= 5
    row = int(SMALL.cy_px - SMALL.fy_px * 0.027 / 0.4)  # the red band
    a = render(still)[row].astype(float)
    b = render(moving)[row].astype(float)
    red = lambda im: np.clip(im[:, 2] - im[:, 1], 0, None)  # noqa: E731  (BGR)
    cols = np.arange(len(a))
    ca, cb = (cols * red(a)).sum() / red(a).sum(), (cols * red(b)).sum() / red(b).sum()
    assert cb == pytest.approx(ca, abs=0.3)  # blurred about the middle of the exposure
    assert (red(b) > 4).sum() >= (red(a) > 4).sum() + 4  # 7 px of motion


def test_a_brick_wall_has_mortar_lines_that_fade_with_distance():
    rng = np.random.default_rng(2)
    x, y = rng.uniform(-1, 1, 5000), rng.uniform(0, 0.5, 5000)
    red = (0.42, 0.14, 0.09)
    near = surfaces.brick_gain(x, y, np.full(x.shape, 1e-4), red, 1)
    mortar = np.asarray(surfaces.MORTAR) / np.asarray(red)
    in_joint = np.isclose(near, mortar[None], rtol=1e-6).all(axis=1)
    assert 0.15 < in_joint.mean() < 0.25  # 10 mm joints on 75 x 225 mm courses: ~17 %
    far = surfaces.brick_gain(x, y, np.full(x.shape, 0.2), red, 1)  # footprint wider than a brick
    assert not np.isclose(far, mortar[None], rtol=1e-6).all(axis=1).any()
    wall = Scene(camera=SMALL, wall_colour=red, brick_wall=True, lighting=Lighting(gloss=0.01))
    img = render_layers(wall)[0][:80]
    assert img[..., 1].std() > 0.01 and img[..., 2].mean() > 0
