import numpy as np
import pytest

from rangebearing.core.blobs import find_blobs, mask_centroid


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


def test_mask_centroid_of_a_rectangle():
    mask = np.zeros((10, 10), np.uint8)
    mask[2:4, 3:7] = 255
    x, y, area = mask_centroid(mask)
    assert (x, y, area) == pytest.approx((4.5, 2.5, 8))
    assert mask_centroid(np.zeros((4, 4), np.uint8)) is None
