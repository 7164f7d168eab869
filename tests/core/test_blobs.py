import numpy as np
import pytest

from rangebearing.core.blobs import find_boxes, mask_centroid


def test_find_boxes_maps_downscaled_boxes_to_full_resolution():
    mask = np.zeros((20, 30), np.uint8)
    mask[4:8, 10:20] = 255
    (box,) = find_boxes(mask, scale=2)
    assert box.tolist() == [20, 8, 20, 8]
    assert box.dtype == np.int64


def test_find_boxes_drops_small_regions_and_separates_regions():
    mask = np.zeros((20, 30), np.uint8)
    mask[2:6, 2:8] = 255
    mask[10:16, 15:25] = 255
    mask[18, 28] = 255
    assert sorted(find_boxes(mask, min_area_px=4).tolist()) == [[2, 2, 6, 4], [15, 10, 10, 6]]
    assert find_boxes(np.zeros((5, 5), np.uint8)).shape == (0, 4)


def test_mask_centroid_of_a_rectangle():
    mask = np.zeros((10, 10), np.uint8)
    mask[2:4, 3:7] = 255
    x, y, area = mask_centroid(mask)
    assert (x, y, area) == pytest.approx((4.5, 2.5, 8))
    assert mask_centroid(np.zeros((4, 4), np.uint8)) is None
