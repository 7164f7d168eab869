"""Limbs of landmarks cut at a side (core/limbs.py, core/edges.limb with the chromaticity mixture)."""

import math

import numpy as np
import pytest

from rangebearing.core.limb_edge import limb
from rangebearing.core.limbs import at_frame_edges, cut_sides, measure_columns, outline_centre
from rangebearing.core.measure import Rows
from rangebearing.core.structure import Candidate
from rangebearing.core.types import LandmarkGeometry

GEOMETRY = LandmarkGeometry()
F_PX = 634.0


def _mixed(n, edge, band_e, band_s, bg_e, bg_s, blur=None):
    """Column profiles (excess, sum) of a band up to sub-pixel column ``edge`` over a background, mixed by
    coverage in linear light, then blurred alike (``blur``: a symmetric kernel), and their ratio."""
    cols = np.arange(n, dtype=np.float64)
    cover = np.clip(edge - (cols - 0.5), 0.0, 1.0)
    e = cover * band_e + (1 - cover) * bg_e
    s = cover * band_s + (1 - cover) * bg_s
    if blur is not None:
        e, s = (np.convolve(np.pad(v, len(blur) // 2, mode="edge"), blur, "valid") for v in (e, s))
    return e / s, e, s


@pytest.mark.parametrize("edge", [20.0, 20.4])
@pytest.mark.parametrize("blur", [None, np.array([0.25, 0.5, 0.25])])
def test_a_limb_darker_than_a_bright_background_is_found_where_it_is(edge, blur):
    # a cylinder's band darkens towards its limb (shading ~ cos): 0.5 of its sum far inside, 0.05 at the limb,
    # against a bright grey wall (sum 1.5); the band's chromaticity is 0.6 everywhere, the wall's 0
    n = 40
    x = np.arange(n, dtype=np.float64)
    band_s = 0.05 + 0.45 * np.clip((edge - x) / edge, 0.0, 1.0)
    q, e, s = _mixed(n, edge, 0.6 * band_s, band_s, 0.0, 1.5, blur)
    # blurred, the next columns' chromaticity is still a trace above the wall's: a few thousandths of a pixel
    assert limb(q, 5, n - 1, 0.6, (e, s)) == pytest.approx(edge, abs=1e-6 if blur is None else 0.01)
    # the chromaticity alone is no coverage mix: the bright wall dominates a mixed column, the edge moves in
    assert limb(q, 5, n - 1, 0.6) < edge - 0.3


def test_a_limb_with_the_mixture_going_left_is_the_mirror_image():
    q, e, s = _mixed(40, 20.3, 0.06, 0.1, 0.02, 1.2)
    mirror = [v[::-1].copy() for v in (q, e, s)]
    assert limb(mirror[0], 34, 0, 0.6, (mirror[1], mirror[2])) == pytest.approx(39 - 20.3, abs=1e-6)


def _frame(x0, x1, front=None):
    """A crisp landmark (red rows 20-35, white 35-75, blue 75-90) from sub-pixel column ``x0`` to ``x1``
    over a grey wall; ``front``: ``(column, colour)``, something nearer hiding every column left of it
    (``"landmark"``: a nearer landmark's bands and body, the same colours row for row)."""
    w = 160
    cols = np.arange(w, dtype=np.float64)
    cover = np.clip(np.minimum(x1 - (cols - 0.5), (cols + 0.5) - x0), 0.0, 1.0)
    lin = np.full((120, w, 3), 0.30)
    for (r0, r1), rgb in (((20, 35), (0.70, 0.07, 0.06)), ((35, 75), (0.85,) * 3), ((75, 90), (0.06, 0.12, 0.65))):
        lin[r0:r1] = cover[:, None] * np.array(rgb) + (1 - cover[:, None]) * lin[r0:r1]
        if front is not None and front[1] == "landmark":
            lin[r0:r1, : front[0]] = rgb
    if front is not None and front[1] != "landmark":
        lin[:, : front[0]] = front[1]
    return np.round(255.0 * lin[..., ::-1] ** (1 / 2.2)).astype(np.uint8)


def _cut_both(x0, x1, visible):
    return Candidate((x0, 20, x1 - x0, 15), (x0, 76, x1 - x0, 15), 40.0, False, False, True, True, visible)


ROWS = Rows(27.5, 82.5, 40.0, 0.1, False, False)


def _centre(limb_px, right):
    return outline_centre(limb_px, right, 0.5 * (160 - 1), F_PX, ROWS.white_px, GEOMETRY)


def test_a_partly_hidden_landmark_cut_on_both_sides_is_placed_from_the_side_that_falls_like_a_limb():
    # a nearer landmark in front hides everything left of column 50: its bands run on into this one's, so
    # only the right side (a limb at 74.3 before the wall) falls off; the moments would sit ~5 px left
    img = _frame(40.3, 74.3, (50, "landmark"))
    x, sigma = measure_columns(img, _cut_both(50, 74, 0.7), (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS)
    assert x == pytest.approx(_centre(74.3, True), abs=0.05)
    assert sigma > 0


def test_both_sides_falling_a_whole_outline_apart_place_it_at_their_midpoint():
    half = ROWS.white_px * GEOMETRY.radius_m / (GEOMETRY.height_m - 2 * GEOMETRY.band_height_m)
    half *= 1.0 - GEOMETRY.radius_m / (F_PX * 0.04 / ROWS.white_px + GEOMETRY.radius_m)
    x0 = 40.2
    img = _frame(x0, x0 + 2 * half)
    x, _ = measure_columns(img, _cut_both(41, 74, 0.9), (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS)
    assert x == pytest.approx(x0 + half, abs=0.05)


def test_a_side_hidden_by_something_of_another_colour_leaves_the_side_unknown():
    # a grey-green part in front left of column 50: both sides fall off, 24 px apart, not a whole outline
    img = _frame(40.3, 74.3, (50, (0.2, 0.35, 0.2)))
    assert measure_columns(img, _cut_both(50, 74, 0.7), (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS) is None


def test_a_landmark_seen_whole_but_marked_cut_on_both_sides_keeps_its_moments():
    img = _frame(40.3, 74.3)
    c = _cut_both(40, 74, 1.0)
    assert measure_columns(img, c, (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS) is None
    assert math.isfinite(c.visible)


def test_where_the_chroma_is_blurred_more_than_the_luma_the_chromaticity_edge_stands():
    # 4:2:0 chroma / colour denoise: the band's excess spread over ~7 columns, its brightness sharp (a grey
    # background about as bright as the band); the mixture (one blur for both) does not hold there, so the
    # limb is the chromaticity's own two-level edge
    q, e, s = _mixed(40, 20.3, 0.18, 0.3, 0.0, 0.35)
    e = np.convolve(np.pad(e, 3, mode="edge"), np.full(7, 1 / 7), "valid")
    q = e / s
    level = float(np.median(q[5:10]))
    assert limb(q, 7, 39, level, (e, s)) == limb(q, 7, 39, level)


@pytest.mark.parametrize("marked", [(True, True), (False, True), (True, False)])
def test_beside_a_nearer_landmark_the_far_side_is_the_limb_whatever_the_search_marked_there(marked):
    # a nearer landmark's white body hides everything left of column 50 (it falls off like a limb there too);
    # the search marked a side cut (a band of this one ran on into a same-coloured wall, or the nearer
    # landmark beside it): the right limb at 74.3 places it, never the nearer landmark's edge
    import dataclasses

    from rangebearing.core.structure import occluded_sides

    img = _frame(40.3, 74.3, (50, (0.85, 0.85, 0.85)))
    c = Candidate((50, 20, 24, 15), (50, 76, 24, 15), 40.0, False, False, *marked, 0.7)
    near = Candidate((10, 10, 40, 22), (10, 100, 40, 22), 60.0, False, False, False, False, 1.0)
    c = occluded_sides([c, near], 2)[0]
    assert c.occluded == "left"
    x, _ = measure_columns(img, c, (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS)
    assert x == pytest.approx(_centre(74.3, True), abs=0.05)
    if marked[1]:  # without the nearer landmark known: no limb (both sides fall off 24 px apart), or the wrong one
        got = measure_columns(img, dataclasses.replace(c, occluded=""), (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS)
        assert got is None or abs(got[0] - _centre(74.3, True)) > 1.0


def test_beside_a_nearer_landmark_a_far_side_whose_band_runs_on_past_the_run_gives_no_limb():
    # the far side marked cut, and the band's colour does run on there (a red box right of column 78 at the
    # red band's rows, beyond the run's end at 74): that limb does not end the run, so the moments stand
    img = _frame(40.3, 74.3, (50, (0.85, 0.85, 0.85)))
    lin = (img.astype(np.float64) / 255.0) ** 2.2
    lin[20:35, 74:110] = (0.06, 0.07, 0.70)  # BGR: red
    img = np.round(255.0 * lin ** (1 / 2.2)).astype(np.uint8)
    c = Candidate((50, 20, 24, 15), (50, 76, 24, 15), 40.0, False, False, True, True, 0.7, occluded="left")
    got = measure_columns(img, c, (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS)
    assert got is None or abs(got[0] - _centre(74.3, True)) < 0.3


def test_a_mast_in_front_of_one_band_does_not_end_the_other_bands_limb():
    # cut on the left (the frame's edge, a neighbour); its robot's dark mast stands in front of the blue band at
    # columns 60-64, inside the run the search saw (to 74): the blue band's "limb" there is the mast's edge; the
    # red band's limb at 74.3 ends the run and places it (the inner limb placed it 14 px left, 3.7 deg at 0.25 m)
    img = _frame(40.3, 74.3)
    img[75:90, 60:64] = 40
    c = Candidate((41, 20, 33, 15), (41, 76, 33, 15), 40.0, False, False, True, False, 0.9)
    x, _ = measure_columns(img, c, (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS)
    assert x == pytest.approx(_centre(74.3, True), abs=0.05)
    # a same-coloured background beside the blue band carries it past the run's end: the inner limb still wins
    lin = (img.astype(np.float64) / 255.0) ** 2.2
    lin[75:90, 60:64] = (0.65, 0.12, 0.06)  # BGR: the band's blue again, no mast
    lin[75:90, 74:110] = (0.65, 0.12, 0.06)
    img = np.round(255.0 * lin ** (1 / 2.2)).astype(np.uint8)
    x, _ = measure_columns(img, c, (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS)
    assert x == pytest.approx(_centre(74.3, True), abs=0.05)


def test_the_frame_edges_cut_a_side_whatever_the_search_saw() -> None:
    inside = Candidate((100, 40, 20, 8), (100, 80, 20, 8), 30.0, False, False, False, False, 1.0)
    at_left = Candidate((0, 40, 20, 8), (0, 80, 20, 8), 30.0, False, False, False, True, 1.0)
    at_right = Candidate((300, 40, 20, 8), (300, 80, 20, 8), 30.0, False, False, False, False, 1.0)
    assert at_frame_edges(inside, 320) == (False, False)
    assert at_frame_edges(at_left, 320) == (True, False)  # the structure's own right cut is not an edge
    assert at_frame_edges(at_right, 320) == (False, True)
    assert cut_sides(at_left, 320) == (True, True)  # the edge and the structure's cut together


def test_a_band_whose_rows_are_off_the_frame_is_skipped_quietly_and_the_other_bands_limb_stands() -> None:
    # the frame ends in the blue band's top rows (a landmark cut by the bottom edge): the blue limb's rows
    # (0.3 band heights about its centre) are all below the frame; numpy warned "Mean of empty slice" there
    import warnings

    img = _frame(40.3, 74.3, (50, "landmark"))[:78]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        x, sigma = measure_columns(img, _cut_both(50, 74, 0.7), (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS)
    assert x == pytest.approx(_centre(74.3, True), abs=0.05)
    assert sigma > 0


def _half_px():
    half = ROWS.white_px * GEOMETRY.radius_m / (GEOMETRY.height_m - 2 * GEOMETRY.band_height_m)
    return half * (1.0 - GEOMETRY.radius_m / (F_PX * 0.04 / ROWS.white_px + GEOMETRY.radius_m))


@pytest.mark.parametrize("visible", [0.8, 1.0])
@pytest.mark.parametrize("moments_off_px", [-3.0, 1.0])
def test_a_landmark_seen_narrower_than_its_silhouette_and_cut_nowhere_is_placed_between_its_limbs(
        visible, moments_off_px):
    # its shaded right side (bands at a quarter of their light from column 64, their chromaticity kept) fell
    # out of the run the search saw (to 68, the limb at 73.5): the moments of what it saw sit left (3 px); the
    # limbs place it. Moments 1 px off agree with the outline: the finer measure, they stand
    half, x0 = _half_px(), 40.2
    cols = np.arange(160, dtype=np.float64)
    cover = np.clip(np.minimum(x0 + 2 * half - (cols - 0.5), (cols + 0.5) - x0), 0.0, 1.0)[:, None]
    shade = np.where(cols >= 64, 0.25, 1.0)[:, None]
    lin = np.full((120, 160, 3), 0.30)
    for (r0, r1), rgb, s in (((20, 35), (0.70, 0.07, 0.06), shade), ((35, 75), (0.85,) * 3, 1.0),
                             ((75, 90), (0.06, 0.12, 0.65), shade)):
        lin[r0:r1] = cover * s * np.array(rgb) + (1 - cover) * lin[r0:r1]
    img = np.round(255.0 * lin[..., ::-1] ** (1 / 2.2)).astype(np.uint8)
    c = Candidate((41, 20, 27, 15), (41, 76, 27, 15), 40.0, False, False, False, False, visible)
    got = measure_columns(img, c, (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS, moments_x_px=x0 + half + moments_off_px)
    if visible < 1.0 and moments_off_px < -2.0:
        assert got is not None and got[0] == pytest.approx(x0 + half, abs=0.1)
    else:  # seen as wide as its silhouette, or the moments near the outline's centre: they stand
        assert got is None


def test_cut_by_the_frame_edge_and_marked_cut_on_the_other_side_it_is_placed_from_that_sides_limb():
    # the frame ends at column 160, inside the landmark (limb at 130.3); the search marked its left side cut
    # (a far landmark's band of its colour touching it): the left limb ends the run and places it
    img = _frame(130.3, 130.3 + 2 * _half_px())
    c = Candidate((131, 20, 29, 15), (131, 76, 29, 15), 40.0, False, False, True, False, 0.6)
    x, sigma = measure_columns(img, c, (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS)
    assert x == pytest.approx(_centre(130.3, False), abs=0.05)
    assert sigma > 0
    # a red box left of it at the red band's rows carries that band on past the run's start: no limb ends
    # the run there, the moments stand
    lin = (img.astype(np.float64) / 255.0) ** 2.2
    lin[20:35, 100:130] = (0.06, 0.07, 0.70)  # BGR: red
    lin[75:90, 100:130] = (0.65, 0.12, 0.06)  # BGR: blue
    img = np.round(255.0 * lin ** (1 / 2.2)).astype(np.uint8)
    got = measure_columns(img, c, (1.0, 1.0, 1.0), GEOMETRY, F_PX, ROWS)
    assert got is None or abs(got[0] - _centre(130.3, False)) < 0.3
