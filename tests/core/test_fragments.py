"""Runs split at white-height steps; fragments joined across what hides the white body."""

import numpy as np

from rangebearing.core.fragments import extend_along_bands, height_steps, join_fragments, lit_like_bands, split_runs

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


def test_a_too_wide_run_whose_band_merged_with_a_wall_is_split_where_both_edges_step_too():
    # two landmarks side by side before a red wall: their red bands run up into it, their inner edges step
    e1 = np.array([12.0] * 10 + [11, 10] + [10.0] * 21)
    e2 = np.array([31.0] * 10 + [32, 33] + [33.0] * 21)
    run_r, run_b = np.full(33, 40.0), np.full(33, 7.0)  # red runs on for 40 rows: merged
    pieces = split_runs([(0, 33)], e1, e2, run_r, run_b, BAND_K, WIDTH_K, 1.7)
    assert pieces == [(0, 11), (11, 33)] or pieces == [(0, 12), (12, 33)]
    flat = np.full(33, 12.0), np.full(33, 33.0)  # one height: one structure (no landmark), kept whole
    assert split_runs([(0, 33)], *flat, run_r, run_b, BAND_K, WIDTH_K, 1.7) == [(0, 33)]


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


def test_two_landmarks_side_by_side_with_agreeing_edges_are_not_one_too_wide_fragment():
    # a far landmark (white 10 rows) beside a nearer one (white 12); the wider window's run took
    # 4 of the far one's columns: it gives them up, and the two stay apart
    red, blue = masks()
    far = (24.0, 31.0, 14.0, 25.0, 10.0, 4.0, 4.0)
    near = (27.0, 40.0, 14.0, 27.0, 12.0, 5.0, 5.0)  # 13 columns for a silhouette of 10.5
    out = join_fragments([far, near], red, blue, BAND_K, WIDTH_K)
    assert [f[:2] for f in out] == [(24.0, 31.0), (31.0, 40.0)]


def landmark_behind_its_camera(red, blue, c0=20, c1=48, board=(34, 60)):
    """A landmark 28 columns wide (white 32 rows) whose own camera board hides its white body from
    ``board[0]`` on, and its bracket a sliver of the blue band."""
    red[10:22, c0:c1] = 255
    blue[54:66, c0:c1] = 255
    blue[54:66, 40:42] = 0  # the bracket
    return (float(c0), float(board[0]), 21.0, 54.0, 32.0, 12.0, 12.0)  # the fragment left of the board


def test_a_fragment_is_extended_along_its_bands_to_the_limb():
    red, blue = masks()
    frag = landmark_behind_its_camera(red, blue)
    c0, c1, seen, hidden, cut_left, cut_right = extend_along_bands(frag, red, blue, BAND_K, WIDTH_K)
    assert (c0, c1) == (20.0, 48.0)
    assert 0.6 < seen < 1.0 and hidden == "blue"  # the body behind the board is not seen; the bracket hid blue
    assert not cut_left and not cut_right  # both bands end together at the limb


def test_an_extension_that_ends_at_something_over_the_red_band_is_cut_there():
    red, blue = masks()
    frag = landmark_behind_its_camera(red, blue)
    red[16:22, 44:48] = 0  # the board over the red band's end: red ends 4 columns before the blue band
    c0, c1, _, _, cut_left, cut_right = extend_along_bands(frag, red, blue, BAND_K, WIDTH_K)
    assert (c0, c1) == (20.0, 44.0) and cut_right and not cut_left


def test_no_extension_when_the_band_runs_on_like_a_wall_or_the_other_band_is_missing():
    red, blue = masks()
    frag = landmark_behind_its_camera(red, blue)
    wall = red.copy()
    wall[10:22, :] = 255  # a red wall at the band's rows: no limb within reach
    assert extend_along_bands(frag, wall, blue, BAND_K, WIDTH_K)[:2] == (20.0, 34.0)
    wall[10:22, :] = 0
    wall[0:22, 14:50] = 255  # a red wall between two masts: it ends, but the "band" has no top
    assert extend_along_bands(frag, wall, blue, BAND_K, WIDTH_K)[:2] == (20.0, 34.0)
    no_blue = blue.copy()
    no_blue[:, 34:] = 0
    assert extend_along_bands(frag, red, no_blue, BAND_K, WIDTH_K)[:2] == (20.0, 34.0)


def test_a_white_body_partly_behind_a_camera_board_is_lit_like_its_bands_a_dark_chassis_is_not():
    hsv = np.zeros((60, 30, 3), np.uint8)
    hsv[0:10, :, 2] = 180  # red band
    hsv[40:50, :, 2] = 120  # blue band (darker in V)
    hsv[10:40, :, 2] = 210  # white body
    rrows, brows = (0, 10), (40, 50)
    assert lit_like_bands(hsv, 0, 30, rrows, brows)
    hsv[12:36, 3:27, 2] = 60  # the robot's own camera board over 64 % of the body: its median is dark
    assert np.median(hsv[10:40, :, 2]) < 0.7 * 150
    assert lit_like_bands(hsv, 0, 30, rrows, brows)
    hsv[10:40, :, 2] = 60  # a dark chassis between a red box and a blue mat
    assert not lit_like_bands(hsv, 0, 30, rrows, brows)
