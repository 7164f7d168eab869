"""Light and camera of the newer presets: spots, highlights, auto exposure, Bayer."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rangebearing.synth import Box, Imaging, LandmarkPose, Lighting, Poster, Scene, random_scene, render
from rangebearing.synth.render import render_linear
from rangebearing.synth.scene import Spot
from rangebearing.synth.sensor import _mosaic, auto_exposure

LM = LandmarkPose(0.5, 0.0)
AE = Imaging(auto_exposure=True, ae_target=0.18)


def _red_band_rows(scene: Scene) -> slice:
    # the red band spans 0.120-0.135 m; the camera is at 0.10 m, f = 634 px, depth ~0.48 m
    cy, f, z = scene.camera.cy_px, scene.camera.fy_px, LM.range_m - 0.0175
    return slice(int(cy - f * 0.033 / z) + 2, int(cy - f * 0.022 / z) - 1)


def test_plain_light_is_the_original_shading():
    rich = Scene(landmarks=(LM,), lighting=Lighting(colour=(1.0, 1.0, 0.999999)))
    plain = Scene(landmarks=(LM,))
    assert not rich.lighting.plain and plain.lighting.plain
    assert np.allclose(render_linear(rich), render_linear(plain), atol=1e-5)


def test_a_spotlight_clips_the_band_and_washes_out_its_colour():
    spot = Spot((0.1, 0.4, 0.3), (0.0, 0.1, 0.5), intensity=0.6, cone_deg=15.0)
    light = Lighting(gloss=0.3, spots=(spot,))
    lit = render(Scene(landmarks=(LM,), lighting=light))
    plain = render(Scene(landmarks=(LM,), lighting=dataclasses.replace(light, spots=())))
    rows, cols = _red_band_rows(Scene()), slice(300, 340)
    band, ref = lit[rows, cols].astype(int), plain[rows, cols].astype(int)
    assert ref[..., 2].max() < 255 and band[..., 2].max() == 255  # R clipped
    assert band[..., 1].max() > ref[..., 1].max() + 60  # G rises: less saturated


def test_auto_exposure_undoes_the_light_level():
    scene = Scene(landmarks=(LM,), imaging=AE)
    dim = dataclasses.replace(scene, lighting=Lighting(colour=(0.25,) * 3, ambient_colour=(0.25,) * 3))
    lin, lin_dim = render_linear(scene), render_linear(dim)
    assert auto_exposure(lin_dim, dim) == pytest.approx(4 * auto_exposure(lin, scene), rel=1e-3)
    diff = np.abs(render(scene).astype(int) - render(dim).astype(int))
    assert diff.mean() < 1.0


def test_a_bright_window_behind_darkens_the_landmark():
    scene = Scene(landmarks=(LM,), imaging=AE, wall_distance_m=1.0)
    window = Poster(-0.15, 0.15, 0.0, 0.5, (1.0, 1.0, 1.0), emission=6.0)
    backlit = dataclasses.replace(scene, posters=(window,))
    assert auto_exposure(render_linear(backlit), backlit) < 0.6 * auto_exposure(render_linear(scene), scene)
    body = (slice(225, 255), slice(312, 328))  # the white body
    assert render(backlit)[body].mean() < 0.75 * render(scene)[body].mean()


def test_bayer_mosaic_keeps_a_flat_colour():
    flat = np.zeros((8, 8, 3), np.float32) + np.array([0.6, 0.2, 0.1], np.float32)
    mos = _mosaic(flat)
    assert mos[0, 0] == pytest.approx(0.6) and mos[0, 1] == pytest.approx(0.2)
    assert mos[1, 1] == pytest.approx(0.1)
    scene = Scene(imaging=Imaging(bayer=True), wall_distance_m=None,
                  floor_colour=(0.5, 0.3, 0.2), lighting=Lighting(ambient=1.0, exposure=1.0))
    img = render(scene).astype(int)
    floor = img[300:, 10:-10]
    ref = render(dataclasses.replace(scene, imaging=Imaging())).astype(int)[300:, 10:-10]
    assert np.abs(floor - ref).max() <= 2


def test_lighting_preset_covers_every_kind_of_light():
    rng = np.random.default_rng(8)
    scenes = [random_scene(rng, "lighting") for _ in range(60)]
    assert any(s.lighting.spots for s in scenes)
    assert any(any(p.emission > 0 for p in s.posters) or max(s.background_colour) > 1 for s in scenes)
    assert any(max(s.lighting.colour) < 0.25 for s in scenes)  # dim
    assert any(max(s.lighting.colour) > 1.4 for s in scenes)  # bright
    tints = [max(s.lighting.colour) / min(s.lighting.colour) for s in scenes]
    assert max(tints) > 1.6  # warm or coloured
    assert all(s.imaging.auto_exposure and s.imaging.bayer for s in scenes)
    assert any(s.imaging.ae_error > 1.3 for s in scenes)  # an over-shooting AE loop


def test_floor_texture_varies_the_albedo_around_its_mean():
    flat = Scene(wall_distance_m=None, lighting=Lighting(ambient=1.0, exposure=1.0))
    textured = dataclasses.replace(flat, floor_texture=0.1, texture_seed=3)
    a, b = render_linear(flat)[300:], render_linear(textured)[300:]
    ratio = b[..., 1] / a[..., 1]
    assert abs(ratio.mean() - 1.0) < 0.06 and 0.03 < ratio.std() < 0.15  # 0.3 m blotches: few in view
    again = render_linear(dataclasses.replace(textured))[300:]
    assert np.array_equal(b, again)  # the seed fixes the pattern
    other = render_linear(dataclasses.replace(textured, texture_seed=4))[300:]
    assert not np.array_equal(b, other)


def test_vignetting_darkens_the_corners_by_its_amount():
    grey = Scene(wall_distance_m=0.5, wall_colour=(0.4, 0.4, 0.4), camera_height_m=0.1,
                 lighting=Lighting(ambient=1.0, exposure=1.0), imaging=Imaging(vignetting=0.3, gamma=1.0))
    img = render(grey).astype(float)
    assert img[0, 0, 1] / img[240, 320, 1] == pytest.approx(0.7, abs=0.02)


def test_a_board_between_the_light_and_the_landmark_shadows_it():
    # light from above and behind the camera; a board 0.17-0.19 m up at z = 0.40 m is
    # above the camera's view of the landmark but on the way from it to the light
    light = Lighting(direction=(0.0, 1.0, -1.0), gloss=0.05)
    lm = LandmarkPose(0.5, 0.0)
    board = Box(0.0, 0.40, 0.2, 0.01, 0.17, 0.19, (0.5, 0.5, 0.5))
    body = (slice(230, 250), slice(310, 330))
    open_sky = render_linear(Scene(landmarks=(lm,), lighting=light))[body].mean()
    shaded = render_linear(Scene(landmarks=(lm,), lighting=light, boxes=(board,)))[body].mean()
    assert shaded == pytest.approx(light.ambient * 0.85, rel=0.01)  # ambient only: in full shadow
    assert open_sky > 1.8 * shaded


def test_a_red_wall_tints_the_white_body_a_little():
    lm, light = LandmarkPose(0.5, 0.0), Lighting(gloss=0.05)
    body = (slice(235, 245), slice(300, 305))
    grey = render_linear(Scene(landmarks=(lm,), lighting=light))[body].mean(axis=(0, 1))
    red = render_linear(Scene(landmarks=(lm,), lighting=light, wall_colour=(0.7, 0.07, 0.06)))[body]
    r, g, b = red.mean(axis=(0, 1))
    assert r == pytest.approx(grey[0], rel=0.02) and 0.8 * grey[1] < g < 0.95 * grey[1] and b < 0.95 * grey[2]
