"""The column scan: the event-based search against a plain per-column reference, and the stacked windows
against each window scanned on its own."""

import numpy as np
import pytest

from rangebearing.core.columns import TOP_TOL, WHITE_SHARE, _run_medians, bridge, column_edges, runs, window_runs


def reference_column(red, blue, white):
    """``(ok, y1, y2, run_r, run_b)`` of one column, pixel by pixel, as the docstring of column_edges says."""
    h = len(red)
    pairs = []
    for y2 in range(1, h):
        if not blue[y2] or blue[y2 - 1]:
            continue  # not a blue top
        bottoms = [y for y in range(y2) if red[y] and not red[y + 1]]
        if not bottoms:
            continue
        y1 = bottoms[-1]
        gap = y2 - y1 - 1
        whites = int(sum(white[y1 + 1 : y2]))
        if gap < 2 or whites < WHITE_SHARE * gap:
            continue
        pairs.append((whites / gap, y1, y2))
    best = None
    if pairs:  # the top-most of those nearly as white as the whitest
        whitest = max(p[0] for p in pairs)
        best = min((p for p in pairs if p[0] >= whitest - TOP_TOL), key=lambda p: p[2])
    if best is None:
        y1, y2, ok = -1, 0, False
        run_r = 0 if red[0] else -1
    else:
        _, y1, y2, ok = (*best, True)
        start = y1
        while start > 0 and red[start - 1]:
            start -= 1
        run_r = y1 - start + 1
    end = y2
    while end < h and blue[end]:
        end += 1
    return ok, y1, y2, run_r, end - y2


def random_window(rng, h, w):
    """Columns of class runs (none/red/blue/white, 1-4 rows long) plus white speckle."""
    cls = np.zeros((h, w), int)
    for x in range(w):
        y = 0
        while y < h:
            n = int(rng.integers(1, 5))
            cls[y : y + n, x] = rng.integers(0, 4)
            y += n
    white = (cls == 3) | (rng.random((h, w)) < 0.15)
    return cls == 1, cls == 2, white & (cls == 0) | (cls == 3)


def window_images(red, blue, white):
    """The HSV image (white: low S, every pixel bright) and the 8-bit red and blue masks of a class window."""
    hsv = np.zeros((*white.shape, 3), np.uint8)
    hsv[..., 1] = np.where(white, 10, 200)
    hsv[..., 2] = 200
    return hsv, (red.astype(np.uint8) * 255, blue.astype(np.uint8) * 255)


@pytest.mark.parametrize("seed", range(6))
def test_column_edges_match_a_pixel_by_pixel_reference(seed):
    rng = np.random.default_rng(seed)
    for _ in range(40):
        h, w = int(rng.integers(1, 30)), int(rng.integers(1, 12))
        red, blue, white = random_window(rng, h, w)
        got = column_edges(red, blue, white)
        for x in range(w):
            assert tuple(int(a[x]) for a in got) == tuple(int(v) for v in reference_column(red[:, x], blue[:, x],
                                                                                          white[:, x]))


def test_stacked_windows_give_each_window_its_own_runs():
    rng = np.random.default_rng(7)
    h, w = 60, 90
    red, blue, white = random_window(rng, h, w)
    hsv, masks = window_images(red, blue, white)
    wins = [(0, 60, 0, 30), (5, 25, 20, 50), (10, 58, 40, 90), (30, 35, 0, 4), (0, 8, 60, 61)]
    got = window_runs(*masks, hsv, wins)
    for (y0, y1, x0, x1), found in zip(wins, got):
        ok, e1, e2, run_r, run_b = column_edges(red[y0:y1, x0:x1], blue[y0:y1, x0:x1], white[y0:y1, x0:x1])
        ok, e1, e2 = bridge(ok, e1, e2)
        want = [
            (s0, s1, *(float(np.median(v[s0:s1])) for v in (e2 - e1 - 1, run_r, run_b, e1, e2)))
            for s0, s1 in runs(ok, e1, e2)
        ]
        assert found == want


@pytest.mark.parametrize("seed", range(4))
def test_a_window_searched_alone_gives_the_runs_it_gets_in_a_stack(seed):
    # a lone window takes the unpadded path (its masks transposed as they are): the same runs and medians
    rng = np.random.default_rng(20 + seed)
    h, w = 40, 70
    red, blue, white = random_window(rng, h, w)
    hsv, masks = window_images(red, blue, white)
    wins = [(0, 40, 0, 25), (3, 33, 20, 70), (8, 40, 10, 45)]  # one stack: each within 4x of the tallest
    stacked = window_runs(*masks, hsv, wins)
    assert any(stacked)
    for win, found in zip(wins, stacked):
        assert window_runs(*masks, hsv, [win]) == [found]


@pytest.mark.parametrize("n_runs", [1, 3])
def test_run_medians_are_numpys_medians(n_runs):
    rng = np.random.default_rng(n_runs)
    values = rng.integers(-5, 40, (5, 50)).astype(np.float64)
    bounds = np.sort(rng.choice(np.arange(51), 2 * n_runs, replace=False))
    s0, s1 = bounds[0::2], bounds[1::2]
    got = _run_medians(values, s0, s1)
    assert got.shape == (5, n_runs)
    for q, (a, z) in enumerate(zip(s0, s1)):
        assert got[:, q].tolist() == np.median(values[:, a:z], axis=1).tolist()


def test_a_landmark_above_its_robot_wins_the_column_over_the_robots_whiter_red_white_blue():
    # the landmark: red 2-3, body 4-11 (one bluish rim row), its blue band merged with a blue wall 12-15;
    # its robot below: red top plate 20-21, pale bumper 22-26 (all white), blue floor 27-
    h = 32
    red, blue, white = np.zeros(h, bool), np.zeros(h, bool), np.zeros(h, bool)
    red[2:4] = True
    white[4:11] = True
    blue[12:16] = True
    red[20:22] = True
    white[22:27] = True
    blue[27:] = True
    ok, y1, y2, _, _ = column_edges(red[:, None], blue[:, None], white[:, None])
    assert ok[0] and (y1[0], y2[0]) == (3, 12)
    assert reference_column(red, blue, white)[:3] == (True, 3, 12)
