"""core.stats: np.median's values by a partial sort."""

import numpy as np
import pytest

from rangebearing.core.stats import median, median_rows


@pytest.mark.parametrize("dtype", [np.uint8, np.int64, np.float32, np.float64])
@pytest.mark.parametrize("n", [1, 2, 3, 4, 7, 8, 9, 16, 33])
def test_median_is_numpys(dtype, n):
    rng = np.random.default_rng(n)
    for _ in range(20):
        a = (rng.normal(size=n) * 50 + 100).astype(dtype)
        assert median(a) == float(np.median(a))
        b = (rng.normal(size=(n, 3)) * 50 + 100).astype(dtype)
        want = np.median(b, axis=0)
        got = median_rows(b)
        assert got.dtype == want.dtype and np.array_equal(got, want)


def test_median_by_hand_and_nan():
    assert median(np.array([3, 1, 2], np.uint8)) == 2.0
    assert median(np.array([250, 255], np.uint8)) == 252.5  # no uint8 overflow in the middle pair
    assert median(np.array([[1.0, 4.0], [2.0, 3.0]])) == 2.5  # flattened, as np.median
    assert np.isnan(median(np.array([1.0, np.nan, 0.5], np.float32)))
    rows = median_rows(np.array([[1.0, 2.0], [np.nan, 4.0], [3.0, 6.0]]))
    assert np.isnan(rows[0]) and rows[1] == 4.0
