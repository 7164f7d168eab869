"""Runs split at white-height steps; fragments joined across what hides the white body."""

import numpy as np

from rangebearing.core.fragments import height_steps, join_fragments

WIDTH_K, BAND_K = 35 / 40, 15 / 40


def test_a_run_no_wider_than_its_silhouette_is_not_split_however_its_edges_curve():
    # a close cylinder's inner edges are arcs: smooth, symmetric, one landmark
    x = np.linspace(-1, 1, 28)
    e1 = 10 + 3 * (1 - np.sqrt(1 - 0.95 * x**2))
    e2 = 43 + 4 * (1 - np.sqrt(1 - 0.95 * x**2))
    assert height_steps(e1, e2, WIDTH_K) == [(0, 28)]


def test_a_too_wide_run_is_split_where_both_edges_step():
    e1 = np.array([12.0] * 10 + [11, 10] + [10.0] * 21)
    e2 = np.array([31.0] * 10 + [32, 33] + [33.0] * 21)  # white 18 rows, then 22 rows
    pieces = height_steps(e1, e2, WIDTH_K)
    assert pieces == [(0, 11), (11, 33)] or pieces == [(0, 12), (12, 33)]


def test_no_split_when_the_taller_piece_would_not_be_a_whole_silhouette():
    e1 = np.array([12.0] * 30 + [10.0] * 10)  # the taller part is 10 of its 19 columns: not in front
    e2 = np.array([31.0] * 30 + [33.0] * 10)
    assert height_steps(e1, e2, WIDTH_K) == [(0, 40)]


def masks(h=80, w=80):
    return np.zeros((h, w), np.uint8), np.zeros((h, w), np.uint8)


def test_fragments_are_joined_across_a_gap_where_a_band_runs_on():
    red, blue = masks()
    red[10:20, 10:38] = 255  # the red band runs on behind the obstacle (columns 16-30)
    frags = [(10.0, 16.0, 19.0, 52.0, 32.0, 10.0, 10.0), (30.0, 38.0, 19.0, 52.0, 32.0, 10.0, 10.0)]
    (joined,) = join_fragments(frags, red, blue, BAND_K, WIDTH_K)
    assert joined[:2] == (10.0, 38.0)


def test_fragments_are_not_joined_across_a_gap_without_bands_or_too_wide():
    red, blue = masks()
    frags = [(10.0, 16.0, 19.0, 52.0, 32.0, 10.0, 10.0), (30.0, 38.0, 19.0, 52.0, 32.0, 10.0, 10.0)]
    assert len(join_fragments(frags, red, blue, BAND_K, WIDTH_K)) == 2  # nothing of the bands in the gap
    red[10:20, :] = 255
    far = [frags[0], (50.0, 58.0, 19.0, 52.0, 32.0, 10.0, 10.0)]  # 48 columns: more than one silhouette
    assert len(join_fragments(far, red, blue, BAND_K, WIDTH_K)) == 2


def test_one_structure_found_in_two_windows_is_one_fragment():
    red, blue = masks()
    frags = [(10.0, 30.0, 19.0, 52.0, 32.0, 10.0, 10.0), (12.0, 38.0, 20.0, 52.0, 31.0, 10.0, 10.0)]
    (joined,) = join_fragments(frags, red, blue, BAND_K, WIDTH_K)
    assert joined[:2] == (10.0, 38.0) and joined[4] == 31.0  # the widest member's edges
