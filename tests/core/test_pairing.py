import math

from rangebearing.core.pairing import PairingLimits, pair_bands, pair_score
from rangebearing.core.types import Blob, LandmarkGeometry

GEO = LandmarkGeometry()


def band(cx, cy, w, h):
    return Blob(cx, cy, w * h, (int(cx - w / 2), int(cy - h / 2), w, h))


def landmark_at(cx, top, w):
    """Red and blue bands of a landmark whose band width is w pixels."""
    h = round(w * 15 / 35)
    spacing = w * 55 / 35
    return band(cx, top, w, h), band(cx, top + spacing, w, h)


def test_a_true_landmark_pairs():
    r, b = landmark_at(100, 50, 30)
    assert pair_score(r, b, GEO, PairingLimits()) < 0.1
    (p,) = pair_bands([r], [b], GEO)
    assert p.red is r and p.blue is b


def test_blue_above_red_is_rejected():
    r, b = landmark_at(100, 50, 30)
    assert pair_bands([b], [r], GEO) == []


def test_misaligned_and_far_apart_pairs_are_rejected():
    r, b = landmark_at(100, 50, 30)
    side = band(100 + 40, b.cy_px, 30, 13)
    far_below = band(100, 50 + 200, 30, 13)
    assert pair_bands([r], [side, far_below], GEO) == []


def test_bands_of_very_different_width_are_rejected():
    r, _ = landmark_at(100, 50, 30)
    wide_blue = band(100, 50 + 47, 90, 13)
    assert pair_bands([r], [wide_blue], GEO) == []


def test_a_big_red_wall_is_not_a_band():
    wall = band(100, 40, 30, 80)  # tall red region over a blue band
    _, b = landmark_at(100, 50, 30)
    assert pair_bands([wall], [b], GEO) == []


def test_each_blob_joins_one_landmark_and_several_landmarks_pair():
    pairs_in = [landmark_at(x, 60 + i * 3, w) for i, (x, w) in enumerate([(50, 20), (150, 30), (300, 12)])]
    reds = [p[0] for p in pairs_in]
    blues = [p[1] for p in pairs_in][::-1]
    pairs = pair_bands(reds, blues, GEO)
    assert len(pairs) == 3
    assert {(p.red.cx_px, p.blue.cx_px) for p in pairs} == {(50, 50), (150, 150), (300, 300)}
    assert all(math.isclose(p.red.cx_px, p.blue.cx_px) for p in pairs)


def test_max_pairs_caps_the_result():
    pairs_in = [landmark_at(40 + 60 * i, 60, 20) for i in range(5)]
    assert len(pair_bands([p[0] for p in pairs_in], [p[1] for p in pairs_in], GEO, max_pairs=3)) == 3
