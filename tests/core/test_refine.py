import dataclasses

import numpy as np
import pytest

from rangebearing.core import detect
from rangebearing.core.color import to_hsv
from rangebearing.core.detect import SPACING_AGREE, WHITE_SLACK_PX, refine, spacing_agrees
from rangebearing.core.params import DetectionParams
from rangebearing.core.refine import band_weights, measure_bands, tile_centroids
from rangebearing.core.structure import Candidate
from rangebearing.core.types import LandmarkGeometry

CFG = DetectionParams()
RED, BLUE = np.array([40, 40, 200.0]), np.array([200, 60, 30.0])
WHITE, BLACK = np.array([220, 220, 220.0]), np.array([15, 15, 15.0])


@pytest.fixture
def raw_moments(monkeypatch):
    """The bands' moments as measured: the outline correction (:func:`.limbs.moments_outline`, tested in
    test_measure.py) moves a column by a share of its distance from the frame's centre, by design."""
    monkeypatch.setattr(detect, "moments_outline", lambda x_px, *_: x_px)


def tiles(*images):
    return np.stack([to_hsv(np.asarray(i, np.float64).round().astype(np.uint8)) for i in images])


def test_horizontal_weights_ramp_with_saturation_and_respect_hue():
    hsv = np.zeros((1, 1, 4, 3), np.uint8)
    hsv[0, 0, :, 0] = (0, 0, 0, 60)  # last pixel green
    hsv[0, 0, :, 1] = (40, 90, 200, 255)
    hsv[0, 0, :, 2] = 200
    w_x, w_y, _ = band_weights(hsv, 1, CFG)
    assert w_x.dtype == np.uint8 and w_y.dtype == np.float32
    assert (w_x[0, 0] / 255).tolist() == pytest.approx([0.0, 0.5, 1.0, 0.0], abs=0.01)
    assert w_y[0, 0, 3] == 0.0


def test_vertical_weights_count_half_blends_the_same_against_white_and_black():
    column = [WHITE, (RED + WHITE) / 2, RED, RED, RED, (RED + BLACK) / 2, BLACK]
    _, w_y, ref = band_weights(tiles(np.array(column).reshape(-1, 1, 3)), 1, CFG)
    # mean chroma (max − min) of the saturated pixels: three reds at 160 and both half blends at 80
    assert ref[0] == pytest.approx((3 * 160 + 2 * 80) / 5, abs=1)
    again = band_weights(tiles(np.array(column).reshape(-1, 1, 3)), 1, CFG, refs=ref)[1]
    assert np.array_equal(again, w_y)  # a known chroma (tracking) gives the same weights
    w = w_y[0, :, 0]
    assert w[0] == 0.0 and w[6] == 0.0
    assert w[1] == pytest.approx(w[5], abs=0.03)  # symmetric, so the centroid stays at the band centre
    _, y, _, ok = tile_centroids(w_y, w_y)
    assert ok[0] and y[0] == pytest.approx(3.0, abs=0.02)


def test_each_tile_uses_its_own_hue():
    red_tile = np.full((3, 3, 3), RED)
    blue_tile = np.full((3, 3, 3), BLUE)
    w_x, _, _ = band_weights(tiles(red_tile, blue_tile), 1, CFG)
    assert w_x[0].min() > 230 and w_x[1].min() > 230
    w_x, _, _ = band_weights(tiles(blue_tile, red_tile), 1, CFG)
    assert w_x.max() == 0  # blue pixels in a red tile (and the reverse) weigh nothing


def test_tile_centroids_by_hand_and_empty_tiles():
    w = np.zeros((2, 4, 5), np.float32)
    w[0, 1, 1] = w[0, 1, 2] = 1.0
    w[0, 1, 3] = 0.5
    x, y, mass, ok = tile_centroids(w, w)
    assert mass[0] == pytest.approx(2.5)
    assert ok.tolist() == [True, False]
    assert x[0] == pytest.approx((1 + 2 + 1.5) / 2.5) and y[0] == pytest.approx(1.0)


GEOMETRY = LandmarkGeometry()


def landmark_image(h: int, x0: int = 40, y0: int = 20, width: int = 40, size=(200, 160)):
    """A flat landmark: red rows [y0, y0+h), white 40/15·h rows, blue h rows, on light grey."""
    img = np.full((*size, 3), 200, np.uint8)
    white = round(h * 40 / 15)
    img[y0 : y0 + h, x0 : x0 + width] = RED
    img[y0 + h : y0 + h + white, x0 : x0 + width] = WHITE
    img[y0 + h + white : y0 + 2 * h + white, x0 : x0 + width] = BLUE
    cand = Candidate((x0, y0, width, h), (x0, y0 + h + white, width, h), float(white), False, False, False, False, 1.0)
    return img, cand, white


@pytest.mark.parametrize("h", [6, 30])  # small bands at full resolution, tall ones at 1/f
def test_refine_finds_band_centres_in_full_resolution_pixels(h):
    img, cand, white = landmark_image(h)
    (found,) = refine(img, [cand], CFG, (1.0, 1.0, 1.0), GEOMETRY, 634.0)
    (rx, ry), (bx, by) = found.red_xy_px, found.blue_xy_px
    assert found.red_mass_px == pytest.approx(40 * h, rel=0.1)  # the weight is about the band area
    assert found.bbox_px == (40, 20, 40, 2 * h + white)
    x_tol = 0.05 if h < 16 else 0.3
    assert ry == pytest.approx(20 + (h - 1) / 2, abs=0.05)
    assert by == pytest.approx(20 + h + white + (h - 1) / 2, abs=0.05)
    assert rx == pytest.approx(59.5, abs=x_tol) and bx == pytest.approx(59.5, abs=x_tol)


def test_a_band_merged_with_a_red_box_above_is_placed_from_its_inner_edge():
    img, cand, white = landmark_image(6, y0=40)  # white 16 rows: the landmark's 15/40/15 exactly
    img[10:40, 20:100] = RED  # a red box behind, touching the band's top edge
    merged = dataclasses.replace(cand, red_merged=True)
    (found,) = refine(img, [merged], CFG, (1.0, 1.0, 1.0), GEOMETRY, 634.0)
    assert found.red_xy_px[1] == pytest.approx(40 + 2.5, abs=0.02)  # the box does not pull it up
    assert found.blue_xy_px[1] == pytest.approx(40 + 6 + white + 2.5, abs=0.02)


@pytest.mark.usefixtures("raw_moments")
@pytest.mark.parametrize("k", [1, 2, 3, 5])
def test_band_centres_move_exactly_with_the_landmark_also_across_the_downscaling_grid(k):
    img, cand, _ = landmark_image(6, y0=30, x0=50)
    moved, cand_k, _ = landmark_image(6, y0=30 + k, x0=50 + k)
    (a,) = refine(img, [cand], CFG, (1.0, 1.0, 1.0), GEOMETRY, 634.0)
    (b,) = refine(moved, [cand_k], CFG, (1.0, 1.0, 1.0), GEOMETRY, 634.0)
    for p, q in ((a.red_xy_px, b.red_xy_px), (a.blue_xy_px, b.blue_xy_px)):
        assert q[0] - p[0] == pytest.approx(k, abs=1e-4) and q[1] - p[1] == pytest.approx(k, abs=1e-4)


def test_a_candidate_whose_band_vanished_is_dropped():
    img, cand, _ = landmark_image(6)
    img[img[..., 0] == BLUE[0]] = 200  # no blue anywhere
    assert refine(img, [cand], CFG, (1.0, 1.0, 1.0), GEOMETRY, 634.0) == []
    assert refine(img, [], CFG, (1.0, 1.0, 1.0), GEOMETRY, 634.0) == []


def test_a_neighbouring_band_inside_the_window_does_not_pull_the_centroid():
    img = np.full((60, 120, 3), 220, np.uint8)
    img[20:30, 20:50] = RED
    img[20:30, 56:86] = RED  # another landmark's red band, 6 px to the right
    alone, other = (20, 20, 30, 10), (56, 20, 30, 10)
    fixes = measure_bands(img, [alone, other], [True, True], [(12, 4), (12, 4)], CFG, (1.0, 1.0, 1.0))
    assert fixes[0].xy_px == pytest.approx((34.5, 24.5), abs=0.05)
    assert fixes[1].xy_px == pytest.approx((70.5, 24.5), abs=0.05)


def test_tile_sums_are_numpys_exact_integer_sums():
    from rangebearing.core.refine import _tile_sums

    rng = np.random.default_rng(3)
    for n, h, w in ((1, 3, 4), (5, 17, 23), (2, 120, 200)):
        a = rng.integers(0, 256, (n * h, w), dtype=np.uint8)
        assert np.array_equal(_tile_sums(a, n), a.reshape(n, -1).sum(axis=1, dtype=np.int64))


def test_a_body_measured_thin_by_colour_bleed_still_agrees_with_its_band_spacing():
    k = GEOMETRY.band_spacing_m / 0.040  # 55 mm of spacing over a 40 mm white body
    assert k == pytest.approx(1.375)
    # 1.05 m under the photoreal-alt camera: spacing 35.2 px, the body 24 px: the search saw 26, the edges 20.4
    assert 35.2 / (20.4 * k) > SPACING_AGREE[1] and spacing_agrees(35.2, 20.4, GEOMETRY, 26.0)
    assert not spacing_agrees(35.2, 20.4, GEOMETRY)  # without the search's body: no slack
    top = SPACING_AGREE[1] * (20.4 + WHITE_SLACK_PX) * k  # the body up to the slack taller, no more
    assert spacing_agrees(top - 0.01, 20.4, GEOMETRY, 40.0) and not spacing_agrees(top + 0.01, 20.4, GEOMETRY, 40.0)
    # the search and the edges alike (10 px at 1/2, 8.03 measured): a spacing of 1.26 bodies is no landmark
    assert not spacing_agrees(13.92, 8.03, GEOMETRY, 10.0)
    # bleed only thins a body: a spacing short of a thick one gets no slack
    low = SPACING_AGREE[0] * 20.4 * k
    assert spacing_agrees(low + 0.01, 20.4, GEOMETRY, 26.0) and not spacing_agrees(low - 0.01, 20.4, GEOMETRY, 26.0)
    assert not spacing_agrees(2.0, 0.0, GEOMETRY, 10.0)  # no body, no landmark
