"""A farther landmark partly behind a nearer one: its bands are followed only up to the nearer one."""

import numpy as np

from rangebearing.core.behind import NearerCleared, without_nearer
from rangebearing.core.fragments import extend_along_bands
from rangebearing.core.structure import Candidate

WIDTH_K, BAND_K = 35 / 40, 15 / 40


def test_the_nearer_candidates_boxes_are_cleared_and_the_masks_kept():
    red, blue = np.full((60, 80), 255, np.uint8), np.full((60, 80), 255, np.uint8)
    near = Candidate((20, 10, 20, 8), (20, 50, 20, 8), 32.0, False, False, False, False, 1.0)  # full resolution
    r, b = without_nearer(red, blue, [near], 2)
    assert not r[5:29, 10:20].any() and not b[5:29, 10:20].any()  # red top to blue bottom, at half resolution
    assert r[4, 10:20].all() and r[5:29, 9].all() and r[5:29, 20].all()
    assert red.all() and blue.all()  # the caller's masks untouched
    assert without_nearer(red, blue, [], 2) == (red, blue)


def test_nearer_cleared_gives_without_nearers_masks_as_the_list_grows():
    rng = np.random.default_rng(29001)
    red, blue = (rng.integers(0, 2, (60, 80), np.uint8) * 255 for _ in range(2))
    red0, blue0 = red.copy(), blue.copy()
    cands = [Candidate((2 * x, 2 * y, 14, 6), (2 * x, 2 * y + 30, 14, 6), 24.0, False, False, False, False, 1.0)
             for x, y in ((3, 2), (20, 10), (31, 30), (5, 40))]
    cleared = NearerCleared(red, blue, 2)
    assert cleared.masks([]) == (red, blue)  # nothing nearer: the masks themselves
    for k in (1, 1, 2, 4):
        got, want = cleared.masks(cands[:k]), without_nearer(red, blue, cands[:k], 2)
        assert all(np.array_equal(g, w) for g, w in zip(got, want))
    assert np.array_equal(red, red0) and np.array_equal(blue, blue0)  # the caller's masks untouched


def test_a_band_running_on_into_a_nearer_landmarks_band_ends_at_its_limb():
    # a farther landmark's own flag hides the left of its white body (columns 38-45); left of that a nearer
    # landmark's red band, at about the same rows, continues its red band: followed through, it has no limb
    red, blue = np.zeros((80, 80), np.uint8), np.zeros((80, 80), np.uint8)
    red[10:20, 38:54] = 255  # the farther band, columns 38-53 (a silhouette of a 20-row white body: 17.5)
    blue[40:49, 38:54] = 255
    red[8:19, 14:38] = 255  # the nearer one's, columns 14-37 (its blue band lower: it is nearer)
    blue[52:64, 14:38] = 255
    frag = (46.0, 54.0, 19.0, 40.0, 20.0, 9.0, 9.0)  # the white body shows in columns 46-53 only
    assert extend_along_bands(frag, red, blue, BAND_K, WIDTH_K)[:2] == (46.0, 54.0)  # no limb: not extended
    near = Candidate((28, 16, 48, 22), (28, 104, 48, 24), 80.0, False, False, False, False, 1.0)
    c0, c1, seen, _, _, _ = extend_along_bands(frag, *without_nearer(red, blue, [near], 2), BAND_K, WIDTH_K)
    assert (c0, c1) == (38.0, 54.0) and seen > 0.5
