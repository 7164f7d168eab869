"""The per-reading sigma: each term moves it the way the measurement says, and the pipeline fills it in."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from rangebearing import Config, Pipeline
from rangebearing.core import uncertainty as u
from rangebearing.core.types import LandmarkGeometry
from rangebearing.synth import LandmarkPose, Scene, render


def test_row_spread_is_half_the_disagreement_of_the_two_estimators_per_band():
    assert u.row_spread_px(10.0, 10.0, False, 50.0, 50.0, False) == 0.0
    # independent errors: the mean of a and b has variance E[(a - b)^2] / 4
    assert u.row_spread_px(10.4, 10.0, False, 50.0, 50.0, False) == pytest.approx(0.2)
    assert u.row_spread_px(10.4, 10.0, False, 49.7, 50.0, False) == pytest.approx(math.hypot(0.2, 0.15))
    # a merged band's moment is not its own: its term is the inner-edge placement's
    assert u.row_spread_px(30.0, 10.0, True, 50.0, 50.0, False) == pytest.approx(u.MERGED_PX)


def test_a_row_from_its_edges_alone_has_its_own_share_of_the_disagreement():
    both = u.row_spread_px(10.4, 10.0, False, 49.7, 50.0, False)
    fits = u.row_spread_px(10.4, 10.0, False, 49.7, 50.0, False, True, True)
    edges_only = [u.FIT_SPREAD * math.sqrt(d * d - u.MOMENT_PX**2) for d in (0.4, 0.3)]
    assert fits == pytest.approx(math.hypot(*edges_only))
    assert fits < both  # the mean's error is half the disagreement; the edges' row errs less
    one = u.row_spread_px(10.4, 10.0, False, 49.7, 50.0, False, True, False)
    assert one == pytest.approx(math.hypot(edges_only[0], 0.15))
    # the moment's own error does not reach a row placed from the edges: a disagreement within it is none
    assert u.row_spread_px(10.0 + 0.9 * u.MOMENT_PX, 10.0, False, 50.0, 50.0, False, True, True) == 0.0
    assert u.row_spread_px(10.0 + 0.9 * u.MOMENT_PX, 10.0, False, 50.0, 50.0, False) > 0.0  # the mean has it
    # a merged band is placed from its inner edge whether or not it "fits"
    assert u.row_spread_px(30.0, 10.0, True, 50.0, 50.0, False, True, True) == pytest.approx(u.MERGED_PX)


def test_a_whole_landmark_near_the_camera_is_seen_whole():
    """The outline of a cylinder is narrower than its white height times diameter/height by
    sqrt((d - r)/(d + r)): a run that spans the outline is the whole landmark."""
    g = LandmarkGeometry()
    white_m = g.height_m - 2 * g.band_height_m
    fy = 600.0
    for d in (0.2, 0.5, 1.5):
        white_px = fy * white_m / (d - g.radius_m)
        outline_px = 2 * fy * g.radius_m / math.sqrt(d * d - g.radius_m**2)
        searched = outline_px / (white_px * g.diameter_m / white_m)  # the run over what the search expected
        assert searched < 1.0
        assert u.silhouette_share(searched, white_px, white_px, fy, g) == pytest.approx(1.0, abs=2e-3)
        half = u.silhouette_share(0.5 * searched, white_px, white_px, fy, g)
        assert half == pytest.approx(0.5, abs=2e-3)  # a half-hidden one stays half
    assert u.silhouette_share(1.0, 50.0, 52.0, fy, g) == 1.0
    # the white height measured at full resolution replaces the search's mask-pixel one
    white_px = fy * white_m / (0.5 - g.radius_m)
    coarse = u.silhouette_share(0.8, white_px * 1.05, white_px, fy, g)
    assert coarse > u.silhouette_share(0.8, white_px, white_px, fy, g)


def test_range_sigma_follows_the_spacing_error_through_the_model():
    base = u.range_sigma_m(1.0, 0.014, 30.0, 0.5, 1.0)
    assert base > 0
    assert u.range_sigma_m(1.0, 0.014, 30.0, 0.5, 1.0, spread_l_px=0.3) > base
    assert u.range_sigma_m(1.0, 0.014, 30.0, 0.5, 0.7) > base  # partly hidden
    assert u.range_sigma_m(1.0, 0.014, 30.0, 1.0, 1.0) > base  # noisier edges
    assert u.range_sigma_m(1.0, 0.014, 30.0, 0.5, 1.0, chroma_blur_px=1.0) > base  # colour blurrier than luma
    assert u.range_sigma_m(1.0, 0.014, 30.0, 0.5, 1.0, cut=(False, True)) > base  # placed from one limb
    assert u.range_sigma_m(1.0, 0.014, 30.0, 0.5, 1.0, clipped=1.0) > base  # over-exposed white body
    # dominated by the spacing term, sigma/range grows like (d - c)/L: double range, half L, four times
    far = u.range_sigma_m(2.0, 0.0, 15.0, 2.0, 1.0, 1.0)
    near = u.range_sigma_m(1.0, 0.0, 30.0, 2.0, 1.0, 1.0)
    assert far / near == pytest.approx(4.0, rel=0.02)
    # never below the model's own error after calibration
    assert u.range_sigma_m(0.5, 0.014, 100.0, 0.0, 1.0) >= u.MODEL_FLOOR * 0.5


def test_a_cut_landmarks_hidden_share_counts_for_what_its_placement_leaves():
    """Range: a cut landmark's rows are scaled for the part of its curve seen (core/arc.py), so its hidden
    share costs less than an uncut one's. Bearing: it is placed from one limb, which the hidden part may be."""
    cut = (True, False)
    cut_whole = u.range_sigma_m(1.0, 0.014, 30.0, 0.5, 1.0, cut=cut)
    uncut_hidden = u.range_sigma_m(1.0, 0.014, 30.0, 0.5, 0.6)
    cut_hidden = u.range_sigma_m(1.0, 0.014, 30.0, 0.5, 0.6, cut=cut)
    assert cut_whole < cut_hidden < uncut_hidden
    b_cut = u.bearing_sigma_rad(0.2, 0.15, 30.0, 634.0, cut=cut)
    b_uncut_hidden = u.bearing_sigma_rad(0.2, 0.15, 30.0, 634.0, visible=0.6)
    b_cut_hidden = u.bearing_sigma_rad(0.2, 0.15, 30.0, 634.0, visible=0.6, cut=cut)
    assert b_cut_hidden > max(b_cut, b_uncut_hidden)
    # a merged band (placed from its inner edge) costs MERGED_PX: more than an edge's noise, less than a pixel
    assert 0.1 < u.MERGED_PX < 1.0


def test_white_clipped_is_the_share_of_the_body_between_the_bands_at_full_scale():
    img = np.full((100, 60, 3), 120, np.uint8)
    img[20:30, 20:40] = (40, 40, 200)  # red band rows 20-29, centre 24.5
    img[30:70, 20:40] = 255  # white body, clipped
    img[70:80, 20:40] = (200, 60, 40)  # blue band, centre 74.5
    red, blue = (29.5, 24.5), (29.5, 74.5)
    assert u.white_clipped(img, red, blue, 20.0) == 1.0
    img[30:50, 20:40] = (230, 235, 240)  # the upper half exposed, not clipped
    assert u.white_clipped(img, red, blue, 20.0) == pytest.approx(0.5, abs=0.05)
    img[30:70, 20:40] = (250, 252, 200)  # a channel below the clip level: not clipped
    assert u.white_clipped(img, red, blue, 20.0) == 0.0
    assert u.white_clipped(img[..., 0], red, blue, 20.0) == 0.0  # a grey frame: no colour to judge


def test_bearing_sigma_grows_with_band_disagreement_hiding_and_splitting():
    base = u.bearing_sigma_rad(0.2, 0.15, 30.0, 634.0)
    assert base >= u.BEARING_FLOOR_RAD
    assert u.bearing_sigma_rad(0.2, 0.15, 30.0, 634.0, spread_x_px=1.0) > base
    assert u.bearing_sigma_rad(0.2, 0.15, 30.0, 634.0, visible=0.6) > base
    one = u.bearing_sigma_rad(0.2, 0.15, 30.0, 634.0, cut=(True, False))
    split = u.bearing_sigma_rad(0.2, 0.15, 30.0, 634.0, cut=(True, True))
    assert one > base and split > base
    assert u.bearing_sigma_rad(0.2, 0.15, 30.0, 634.0, cut=(False, True)) == one
    # off axis a pixel is a smaller angle (cos^2)
    assert u.bearing_sigma_rad(0.5, 2.0, 30.0, 634.0) < u.bearing_sigma_rad(0.0, 2.0, 30.0, 634.0)


def _landmark_columns(chroma_sigma_px: float, luma_sigma_px: float = 0.7) -> np.ndarray:
    """A 100x40 BGR frame: red band rows 10-24, white body 25-64, blue band 65-79 on grey, the same in
    every column; blurred by ``luma_sigma_px`` (all of it), the colour (YCrCb chroma) by ``chroma_sigma_px`` more."""
    img = np.full((100, 40, 3), 90, np.uint8)
    img[10:25] = (40, 40, 200)
    img[25:65] = (205, 205, 205)
    img[65:80] = (190, 50, 40)
    img = cv2.GaussianBlur(img, (1, 0), sigmaX=0.1, sigmaY=luma_sigma_px)
    if chroma_sigma_px > 0:
        ycc = cv2.cvtColor(img, cv2.COLOR_BGR2YCrCb)
        ycc[..., 1:] = cv2.GaussianBlur(ycc[..., 1:], (1, 0), sigmaX=0.1, sigmaY=chroma_sigma_px)
        img = cv2.cvtColor(ycc, cv2.COLOR_YCrCb2BGR)
    return img


def test_chroma_blur_is_the_colours_blur_beyond_the_brightness():
    """Blurred alike, the colour is no blurrier than the luma; colour alone smoothed (4:2:0, colour
    denoise) shows as a blur that grows with the smoothing."""
    def blur(img):
        return u.chroma_blur_px(img, (20.0, 17.0), (20.0, 72.0), 30.0, (1.0, 1.0, 1.0))

    alike = blur(_landmark_columns(0.0))
    assert 0.0 <= alike < 0.35
    # pixel noise makes no blur: a sharp edge in noisy colour reads (close to) none on average
    rng = np.random.default_rng(7)
    sharp = _landmark_columns(0.0).astype(np.int16)
    noisy = [blur(np.clip(sharp + rng.normal(0, 4, sharp.shape), 0, 255).astype(np.uint8)) for _ in range(12)]
    assert float(np.mean(noisy)) < 0.17  # clipping each band's difference at zero read 0.23 here
    mild, strong = blur(_landmark_columns(0.8)), blur(_landmark_columns(1.6))
    assert alike < mild < strong
    assert strong > 1.0
    # nothing to measure: no reading goes wrong, the term is just absent
    assert u.chroma_blur_px(np.zeros((6, 6, 3), np.uint8), (3.0, 1.0), (3.0, 4.0), 2.0, (1.0, 1.0, 1.0)) == 0.0


def test_chroma_blur_of_all_landmarks_at_once_is_each_ones_own():
    """Stacking the landmarks' tiles changes no value: the batch gives each landmark's blur bit for bit,
    a landmark too small to measure gives 0 in its place."""
    a, b = _landmark_columns(0.8), _landmark_columns(1.6)
    frame = np.concatenate((a, np.full((100, 13, 3), 90, np.uint8), b), axis=1)  # two landmarks, 53 px apart
    bands = [((20.0, 17.0), (20.0, 72.0), 30.0), ((2.0, 1.0), (2.0, 4.0), 2.0), ((73.0, 17.0), (73.0, 72.0), 24.0)]
    gains = (1.1, 1.0, 0.9)
    each = [u.chroma_blur_px(frame, r, bl, w, gains) for r, bl, w in bands]
    assert u.chroma_blur_all(frame, bands, gains) == each
    assert each[1] == 0.0 and 0.0 < each[0] < each[2]
    assert u.chroma_blur_all(frame, [], gains) == []


def test_pipeline_readings_carry_sigmas_that_grow_with_sensor_noise():
    cfg = Config()
    clean = Scene(landmarks=(LandmarkPose(0.8, 0.1),))
    noisy = Scene(landmarks=(LandmarkPose(0.8, 0.1),), imaging=clean.imaging.__class__(
        blur_sigma_px=0.8, read_noise=0.05, shot_noise=0.008))
    pipe = Pipeline(cfg.pipeline, track=False)
    sig = {}
    for name, scene in (("clean", clean), ("noisy", noisy)):
        rs, bs = [], []
        for seed in range(3):
            (lm,) = pipe.process(render(scene, np.random.default_rng(seed))).landmarks
            assert lm.range_sigma_m > 0 and lm.bearing_sigma_rad > 0
            rs.append(lm.range_sigma_m)
            bs.append(lm.bearing_sigma_rad)
        sig[name] = (np.median(rs), np.median(bs))
    assert sig["noisy"][0] > 1.15 * sig["clean"][0]
    assert sig["noisy"][1] > 1.1 * sig["clean"][1]


def test_column_scatter_is_noise_not_the_edges_curve_or_the_shading():
    """A noiseless landmark's edges curve (an ellipse seen from below) and shade across the cylinder:
    neither is scatter. Noise is."""
    import rangebearing.core.edges as edges

    seen = []
    orig = edges._column_sigma

    def spy(*args):
        seen.append(orig(*args))
        return seen[-1]

    pipe = Pipeline(Config().pipeline, track=False)
    out = {}
    for noise in (0.0, 0.03):
        seen.clear()
        scene = Scene(landmarks=(LandmarkPose(0.6, -0.2),), imaging=Scene().imaging.__class__(
            blur_sigma_px=0.6, read_noise=noise))
        edges._column_sigma = spy
        try:
            assert pipe.process(render(scene, np.random.default_rng(4))).landmarks
        finally:
            edges._column_sigma = orig
        out[noise] = max(seen)
    assert out[0.0] < 0.03  # px: the smooth curve and the shading are taken out
    assert out[0.03] > 3 * out[0.0]
