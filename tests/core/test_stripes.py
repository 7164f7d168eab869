"""Stripes under camera noise and chains of false candidates (core/stripes.py, core/verify.verdicts)."""

import dataclasses

import numpy as np
import pytest

from rangebearing.core.detect import BandCentroids
from rangebearing.core.stripes import colour, log_error, same
from rangebearing.core.structure import Candidate
from rangebearing.core.types import CameraIntrinsics, LandmarkGeometry
from rangebearing.core.verify import rejection, verdicts

GEOMETRY = LandmarkGeometry()
RED, WHITE, BLUE = (0.70, 0.07, 0.06), (0.85, 0.85, 0.85), (0.06, 0.12, 0.65)
RED_WALL, SKIRTING, MAT = (0.45, 0.03, 0.03), (0.55, 0.55, 0.52), (0.05, 0.08, 0.45)
GREY_WALL = (0.30, 0.30, 0.30)
W, H, LM_W = 320, 110, 40  # frame; a landmark 40 px wide: red rows 20-35, body 35-75, blue 75-90
RED_ROWS, BODY_ROWS, BLUE_ROWS = (20, 35), (35, 75), (75, 90)


def encode(lin, noise=0.0, seed=0):
    """Linear RGB -> 8-bit BGR, with Gaussian noise of ``noise`` 8-bit levels (a camera at high gain)."""
    v = 255.0 * np.clip(lin, 0.0, 1.0)[..., ::-1] ** (1 / 2.2)
    v = v + np.random.default_rng(seed).normal(0.0, noise, v.shape)
    return np.clip(np.round(v), 0, 255).astype(np.uint8)


def room(stripes=True):
    """A red wall over a skirting board over a blue mat (``stripes``), or a grey wall over a grey floor."""
    lin = np.empty((H, W, 3))
    lin[:] = GREY_WALL
    if stripes:
        lin[: RED_ROWS[1]] = RED_WALL
        lin[RED_ROWS[1] : BODY_ROWS[1]] = SKIRTING
        lin[BODY_ROWS[1] :] = MAT
    return lin


def landmark(lin, x0):
    out = lin.copy()
    for rows, paint in ((RED_ROWS, RED), (BODY_ROWS, WHITE), (BLUE_ROWS, BLUE)):
        out[rows[0] : rows[1], x0 : x0 + LM_W] = paint
    return out


def candidate(x0, cut=(False, False), width=LM_W):
    red_box = (x0, RED_ROWS[0], width, RED_ROWS[1] - RED_ROWS[0])
    blue_box = (x0, BLUE_ROWS[0], width, BLUE_ROWS[1] - BLUE_ROWS[0])
    cand = Candidate(red_box, blue_box, 40.0, False, False, cut[0], cut[1], 1.0)
    centre_x = x0 + 0.5 * width - 0.5
    return BandCentroids((centre_x, 27.0), (centre_x, 82.0), red_box, blue_box, 600.0, 600.0, 90.0, 90.0,
                         candidate=cand)


def test_a_colours_noise_is_its_medians_standard_error():
    lin = np.full((30, 30, 3), 0.2)
    quiet, loud = colour(encode(lin, 1.0), (0, 29), (0, 29)), colour(encode(lin, 12.0), (0, 29), (0, 29))
    assert np.allclose(quiet[0], loud[0], rtol=0.1)  # the median stays put
    assert all(log_error(loud, k) > 5 * log_error(quiet, k) for k in range(3))  # its uncertainty grows with the noise
    # one surface under heavy noise: the same colour; a red wall and a white body: not, however noisy
    img = encode(room(), 14.0, seed=3)
    assert same(colour(img, RED_ROWS, (10, 40)), colour(img, RED_ROWS, (200, 230)))
    lm = encode(landmark(room(False), 100), 14.0, seed=3)
    assert not same(colour(lm, BODY_ROWS, (110, 130)), colour(lm, RED_ROWS, (110, 130)))


def dim_room(stripes=True):
    """:func:`room` with a dim red wall: its green and blue channels a few 8-bit levels at high gain."""
    lin = room(stripes)
    if stripes:
        lin[: RED_ROWS[1]] = (0.2, 0.03, 0.02)
    return lin


@pytest.mark.parametrize("width", [12, 20])
def test_stripes_under_camera_noise_are_still_stripes(width):
    # a far candidate on a dim red wall over a skirting board, 24 levels of noise: every draw is stripes
    c = candidate(140, cut=(True, True), width=width)
    assert all("stripes" in (rejection(encode(dim_room(), 24.0, seed=s), c, GEOMETRY) or "") for s in range(30))
    # a real landmark as wide before a grey wall, as noisy: never
    lin = dim_room(False)
    for rows, paint in ((RED_ROWS, RED), (BODY_ROWS, WHITE), (BLUE_ROWS, BLUE)):
        lin[rows[0] : rows[1], 140 : 140 + width] = paint
    assert all(rejection(encode(lin, 24.0, seed=s), candidate(140, width=width), GEOMETRY) is None for s in range(30))


def test_a_bright_channel_that_differs_is_another_colour_however_noisy():
    # noise widens the tolerance of a saturated colour's dark channels only: red 0.2 against red 0.3
    a, b = np.full((12, 12, 3), 0.2), np.full((12, 12, 3), 0.2)
    a[..., 0], a[..., 1:] = 0.30, 0.02
    b[..., 0], b[..., 1:] = 0.20, 0.02
    assert not same(colour(encode(a, 24.0, 1), (0, 11), (0, 11)), colour(encode(b, 24.0, 2), (0, 11), (0, 11)))
    assert same(colour(encode(a, 24.0, 1), (0, 11), (0, 11)), colour(encode(a, 24.0, 2), (0, 11), (0, 11)))


def test_false_candidates_side_by_side_do_not_excuse_each_other():
    # masts cut a skirting board into pieces: three false candidates in a row, each right beside the next
    img = encode(room(), 4.0, seed=2)
    row = [candidate(x, cut=(True, True)) for x in (60, 102, 144)]
    assert rejection(img, row[1], GEOMETRY, others=row) is None  # each neighbour hides what lies beside it
    assert all(w is not None and "stripes" in w for w in verdicts(img, row, GEOMETRY))
    # two real landmarks touching before a grey wall: each excuses the other's columns and both pass
    pair = landmark(landmark(room(False), 100), 140)
    real = [candidate(100, cut=(False, True)), candidate(140, cut=(True, False))]
    assert verdicts(encode(pair, 4.0), real, GEOMETRY) == [None, None]


def test_a_real_landmark_beside_a_false_one_is_judged_on_what_it_really_stands_beside():
    # a real landmark before a grey wall, a false candidate on the stripes of a poster right beside it
    lin = room(False)
    lin[:, 180:] = room()[:, 180:]
    img = encode(landmark(lin, 140), 3.0)
    fake = dataclasses.replace(candidate(182, cut=(True, True)))
    got = verdicts(img, [candidate(140), fake], GEOMETRY)
    assert got[0] is None and "stripes" in got[1]


def test_a_flag_cut_into_silhouettes_is_no_row_of_landmarks():
    from rangebearing.core.types import CameraIntrinsics
    from rangebearing.core.verify import twins

    cam = CameraIntrinsics()
    # a wide flag on the wall, its stripes in the landmark's proportions: the run is split into three
    # silhouettes of one size, each right beside the next, at 0.6 m (55 px between the band centres)
    img = encode(room(), 3.0)
    row = [candidate(x, cut=(x > 60, x < 140)) for x in (60, 100, 140)]
    assert twins(img, row[0], row[1], GEOMETRY, cam) and not twins(img, row[0], row[2], GEOMETRY, cam)
    assert all(w is not None and "one thing cut" in w for w in verdicts(img, row, GEOMETRY, cam=cam))
    # the same pieces far away (their rows 3x closer together: 1.9 m) may be two robots' landmarks, one
    # behind the other: sizes that differ by a few per cent no longer show in the rows
    far = [dataclasses.replace(c, red_xy_px=(c.red_xy_px[0], 60.0), blue_xy_px=(c.blue_xy_px[0], 78.0)) for c in row]
    assert not twins(img, far[0], far[1], GEOMETRY, cam)


def test_far_pieces_are_twins_when_their_band_spacings_agree_and_overlapping_pieces_too():
    from rangebearing.core.types import CameraIntrinsics
    from rangebearing.core.verify import twins

    cam = CameraIntrinsics()
    img = encode(room(), 3.0)

    def piece(x0, width, red_y, blue_y):
        c = candidate(x0, cut=(True, True), width=width)
        return dataclasses.replace(c, red_xy_px=(c.red_xy_px[0], red_y), blue_xy_px=(c.blue_xy_px[0], blue_y))

    # 1.9 m away (18 px between the band centres), 12 px wide, side by side: spacings alike to 0.1 px put
    # them at one depth, their axes 3.6 cm apart: one thing cut
    a = piece(100, 12, 60.0, 78.0)
    assert twins(img, a, piece(112, 12, 60.05, 77.95), GEOMETRY, cam)
    # the same rows within the rows' tolerance, but spacings 0.8 px apart: ~10 cm apart in depth, two robots
    # one behind the other may show so
    assert not twins(img, a, piece(112, 12, 59.6, 78.4), GEOMETRY, cam)
    # pieces that overlap (a wide run cut into silhouettes wider than half its width) are judged as well
    b, c = piece(100, 40, 27.0, 82.0), piece(120, 40, 27.0, 82.0)
    assert twins(img, b, c, GEOMETRY, cam) and twins(img, c, b, GEOMETRY, cam)
    assert not twins(img, b, piece(150, 40, 27.0, 82.0), GEOMETRY, cam)  # 10 px apart: not beside it


def test_pieces_of_a_fat_can_are_twins_when_their_centres_agree_though_their_rows_do_not():
    from rangebearing.core.types import CameraIntrinsics
    from rangebearing.core.verify import twins

    cam = CameraIntrinsics()
    img = encode(room(), 3.0)
    a = candidate(60, cut=(False, True))  # 55 px between the band centres: 0.63 m away

    def rows(c, red_y, blue_y):
        return dataclasses.replace(c, red_xy_px=(c.red_xy_px[0], red_y), blue_xy_px=(c.blue_xy_px[0], blue_y))

    # a can's middle piece is nearer than its end: its bands 2 px farther out each (4 px taller spacing), its
    # centre on the same row: 4 cm nearer, its axis 4 cm over: one can, not two robots
    middle = rows(candidate(100, cut=(True, True)), a.red_xy_px[1] - 2.0, a.blue_xy_px[1] + 2.0)
    assert twins(img, a, middle, GEOMETRY, cam) and twins(img, middle, a, GEOMETRY, cam)
    # the same piece 1.6 cm higher (16 px at 0.63 m): no part of one thing standing on one floor
    assert not twins(img, a, rows(middle, middle.red_xy_px[1] - 16.0, middle.blue_xy_px[1] - 16.0), GEOMETRY, cam)


def test_a_can_lit_from_one_side_grows_lighter_across_its_cut_two_landmarks_meet_darker():
    from rangebearing.core.verify import limbs_between

    a, b = candidate(60, cut=(False, True)), candidate(100, cut=(True, False))
    lin = landmark(landmark(room(False), 60), 100)
    body = lin[BODY_ROWS[0] : BODY_ROWS[1], 60:140]
    # one can, light from its right: its body lighter column by column, the cut between its pieces' levels
    can = lin.copy()
    can[BODY_ROWS[0] : BODY_ROWS[1], 60:140] = body * np.linspace(0.3, 1.0, 80)[None, :, None]
    assert not limbs_between(encode(can, 2.0), a, b)
    # two cylinders in the same light: each darker at its limbs (cos of the normal), two limbs meet at 100
    two = lin.copy()
    two[BODY_ROWS[0] : BODY_ROWS[1], 60:140] = body * np.tile(np.cos(np.linspace(-1.3, 1.3, 40)), 2)[None, :, None]
    assert limbs_between(encode(two, 2.0), a, b)


def test_one_landmark_found_twice_is_no_pair_of_twins():
    from rangebearing.core.types import CameraIntrinsics
    from rangebearing.core.verify import twins

    cam = CameraIntrinsics()
    img = encode(landmark(room(False), 100), 3.0)
    whole = candidate(100)
    # a fragment of it measured apart (its white body partly hidden: another white height, other band boxes),
    # over half its columns and its rows: one landmark twice, not two silhouettes of one wide run
    part = candidate(112, width=24)
    part = dataclasses.replace(part, candidate=dataclasses.replace(
        part.candidate, white_px=34.0, red_bbox_px=(112, 24, 24, 12), blue_bbox_px=(112, 72, 24, 12)))
    assert not twins(img, whole, part, GEOMETRY, cam) and not twins(img, part, whole, GEOMETRY, cam)
    # the same columns split from one run (its rows and white body): twins
    assert twins(img, whole, candidate(112, width=24), GEOMETRY, cam)


def test_a_landmark_is_no_twin_of_stripes_rejected_for_their_own_reason(monkeypatch):
    import rangebearing.core.verify as verify

    # a real landmark (100-140) and, right beside it, a piece of striped wall of its size (141-153): the
    # piece is stripes; the landmark is taken as its twin (as a band of the wall's hue can make it)
    lin = room(False)
    lin[:, 140:] = room()[:, 140:]
    img = encode(landmark(lin, 100), 3.0)
    real, piece = candidate(100, cut=(False, True)), candidate(141, cut=(True, True), width=12)
    monkeypatch.setattr(verify, "twins", lambda bgr, c, o, geometry, cam: c is real and o is piece)
    cam = CameraIntrinsics()
    got = verdicts(img, [real, piece], GEOMETRY, cam=cam)
    assert got[0] is None and "stripes" in got[1]  # the stripes have a reason of their own: no twin of it
    # the same piece of wall cut on both sides (no limb of its own): a piece of something wider stays one
    cut = dataclasses.replace(real, candidate=dataclasses.replace(real.candidate, cut_left=True))
    monkeypatch.setattr(verify, "twins", lambda bgr, c, o, geometry, cam: c is cut and o is piece)
    assert verdicts(img, [cut, piece], GEOMETRY, cam=cam)[0] == verify.TWINNED
    # two pieces of one can, each the other's twin: both stay one thing cut
    a, b = candidate(100, cut=(False, True)), candidate(140, cut=(True, False))
    monkeypatch.setattr(verify, "twins", lambda bgr, c, o, geometry, cam: {c, o} <= {a, b})
    assert verdicts(img, [a, b], GEOMETRY, cam=cam) == [verify.TWINNED] * 2
