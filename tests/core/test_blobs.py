import numpy as np
import pytest

from rangebearing.core.blobs import find_blobs, mask_centroid, weighted_centroid


def test_find_blobs_maps_downscaled_coordinates_to_full_resolution():
    mask = np.zeros((20, 30), np.uint8)
    mask[4:8, 10:20] = 255  # centre (14.5, 5.5) in mask pixels
    (b,) = find_blobs(mask, scale=2.0, offset_px=(100, 50))
    assert b.cx_px == pytest.approx(100 + (14.5 + 0.5) * 2 - 0.5, abs=0.6)
    assert b.cy_px == pytest.approx(50 + (5.5 + 0.5) * 2 - 0.5, abs=0.6)
    assert b.bbox_px == (120, 58, 20, 8)


def test_find_blobs_drops_small_regions_and_separates_regions():
    mask = np.zeros((20, 30), np.uint8)
    mask[2:6, 2:8] = 255
    mask[10:16, 15:25] = 255
    mask[18, 28] = 255
    blobs = find_blobs(mask, min_area_px=4)
    assert len(blobs) == 2


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_weighted_centroid_is_translation_invariant(dtype):
    w = np.zeros((20, 20), dtype)
    w[3:6, 4:9] = 1.0
    w[5, 9] = 0.5
    x0, y0, m0 = weighted_centroid(w)
    x1, y1, m1 = weighted_centroid(np.roll(np.roll(w, 3, axis=1), 7, axis=0))
    assert (x1 - x0, y1 - y0) == pytest.approx((3, 7))
    assert m1 == pytest.approx(m0)


def test_weighted_centroid_sub_pixel_from_partial_weights():
    w = np.zeros((5, 5), np.float32)
    w[2, 1] = 1.0
    w[2, 2] = 1.0
    w[2, 3] = 0.5  # half-covered edge pixel pulls the centroid right
    x, y, _ = weighted_centroid(w)
    assert x == pytest.approx((1 + 2 + 1.5) / 2.5)
    assert y == pytest.approx(2.0)
    assert weighted_centroid(np.zeros((3, 3), np.float32)) is None


def test_mask_centroid_of_a_rectangle():
    mask = np.zeros((10, 10), np.uint8)
    mask[2:4, 3:7] = 255
    x, y, area = mask_centroid(mask)
    assert (x, y, area) == pytest.approx((4.5, 2.5, 8))
    assert mask_centroid(np.zeros((4, 4), np.uint8)) is None
