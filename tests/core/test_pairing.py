import numpy as np

from rangebearing.core.pairing import PairingLimits, pair_bands, pair_scores
from rangebearing.core.types import LandmarkGeometry

GEO = LandmarkGeometry()


def band(cx, cy, w, h):
    """A band box (x, y, w, h) centred near (cx, cy)."""
    return (round(cx - w / 2), round(cy - h / 2), w, h)


def arr(*boxes):
    return np.array(boxes, np.int64).reshape(-1, 4)


def landmark_at(cx, top, w):
    """Red and blue bands of a landmark whose band width is w pixels."""
    h = round(w * 15 / 35)
    spacing = w * 55 / 35
    return band(cx, top, w, h), band(cx, top + spacing, w, h)


def test_a_true_landmark_pairs():
    r, b = landmark_at(100, 50, 30)
    assert pair_scores(arr(r), arr(b), GEO, PairingLimits())[0, 0] < 0.1
    assert pair_bands(arr(r), arr(b), GEO) == [(0, 0)]


def test_blue_above_red_is_rejected():
    r, b = landmark_at(100, 50, 30)
    assert pair_bands(arr(b), arr(r), GEO) == []


def test_misaligned_and_far_apart_pairs_are_rejected():
    r, _ = landmark_at(100, 50, 30)
    side = band(100 + 40, 50 + 30 * 55 / 35, 30, 13)
    far_below = band(100, 50 + 200, 30, 13)
    assert pair_bands(arr(r), arr(side, far_below), GEO) == []


def test_bands_of_very_different_width_are_rejected():
    r, _ = landmark_at(100, 50, 30)
    wide_blue = band(100, 50 + 47, 90, 13)
    assert pair_bands(arr(r), arr(wide_blue), GEO) == []


def test_a_big_red_wall_is_not_a_band():
    wall = band(100, 40, 30, 80)  # tall red region over a blue band
    _, b = landmark_at(100, 50, 30)
    assert pair_bands(arr(wall), arr(b), GEO) == []


def test_each_blob_joins_one_landmark_and_several_landmarks_pair():
    pairs_in = [landmark_at(x, 60 + i * 3, w) for i, (x, w) in enumerate([(50, 20), (150, 30), (300, 12)])]
    reds = [p[0] for p in pairs_in]
    blues = [p[1] for p in pairs_in][::-1]
    pairs = pair_bands(arr(*reds), arr(*blues), GEO)
    assert sorted(pairs) == [(0, 2), (1, 1), (2, 0)]  # blues were given in reverse order


def test_max_pairs_caps_the_result():
    pairs_in = [landmark_at(40 + 60 * i, 60, 20) for i in range(5)]
    assert len(pair_bands(arr(*[p[0] for p in pairs_in]), arr(*[p[1] for p in pairs_in]), GEO, max_pairs=3)) == 3


def test_no_boxes_no_pairs():
    assert pair_bands(arr(), arr(band(10, 10, 20, 8)), GEO) == []
