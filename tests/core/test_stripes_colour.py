"""stripes.colour and log_error: np.median's colour and the MAD of the sorted samples, from a partial sort."""

import math

import numpy as np

from rangebearing.core.stripes import colour, log_error


def _by_sort(region: np.ndarray):
    sub = np.sort(region.reshape(-1, 3), axis=0)
    med = np.median(region.reshape(-1, 3).astype(np.float64), axis=0)
    lin = [(m / 255.0) ** 2.2 for m in med.tolist()]
    return lin, sub


def test_colour_is_the_median_colour_and_its_noise_that_of_the_sorted_samples():
    rng = np.random.default_rng(24501)
    bgr = rng.integers(0, 256, (120, 160, 3), np.uint8)
    bgr[40:60] //= 8  # a dark stretch: small, tied values
    for rows, cols in (((10, 14), (20, 50)), ((30, 90), (5, 150)), ((41, 44), (60, 61)), ((0, 119), (0, 159))):
        got = colour(bgr, rows, cols)
        r0, r1, c0, c1 = rows[0], rows[1] + 1, cols[0], cols[1] + 1
        rs, cs = max(1, (r1 - r0) // 24), max(1, (c1 - c0) // 24)
        want = _by_sort(bgr[r0:r1:rs, c0:c1:cs])
        assert got is not None
        assert np.allclose(got[0], want[0], rtol=1e-12, atol=0)
        assert sorted(got[1][:, 2].tolist()) == want[1][:, 2].tolist()
        for k in range(3):
            assert math.isclose(log_error(got, k), log_error((want[0], want[1]), k), rel_tol=1e-12)
    assert colour(bgr, (50, 40), (0, 10)) is None
