"""White balance from the landmarks' own white bodies, and the two-hypothesis search."""

import dataclasses
import math

import numpy as np
import pytest

from rangebearing.core.balance import (
    balanced_search,
    halfway,
    merge_candidates,
    near_unit,
    second_look,
    white_body_gains,
)
from rangebearing.core.structure import Candidate


def cand(x, y=40, w=20, band=8, white=24):
    """A candidate whose red band is at (x, y), white body below it, then the blue band."""
    return Candidate((x, y, w, band), (x, y + band + white, w, band), float(white), False, False, False, False, 1.0)


def frame_with_body(body_bgr, wall_bgr=(40, 60, 170), c=None):
    img = np.full((120, 160, 3), wall_bgr, np.uint8)  # a muted red wall over the whole frame
    c = c or cand(60)
    x, y, w, h = c.red_bbox_px
    img[y + h : c.blue_bbox_px[1], x : x + w] = body_bgr
    return img, c


def test_a_white_body_under_a_warm_cast_gives_the_gains_that_neutralise_it():
    img, c = frame_with_body((120, 160, 200))  # white under tungsten light
    g = white_body_gains(img, [c])
    body = np.array([120, 160, 200]) * np.array(g)
    assert body.max() - body.min() < 1.0
    assert g[0] > 1.0 > g[2]


def test_a_flag_in_front_of_part_of_the_body_does_not_move_the_median():
    img, c = frame_with_body((180, 180, 180))
    x, y, _, h = c.red_bbox_px
    img[y + h + 8 : y + h + 14, x + 4 : x + 12] = (30, 120, 30)  # a green flag over a quarter of the body
    assert white_body_gains(img, [c]) == pytest.approx((1.0, 1.0, 1.0), abs=0.01)


def test_clipped_and_dark_bodies_do_not_vote():
    img, c = frame_with_body((255, 255, 255))
    assert white_body_gains(img, [c]) is None
    img, c = frame_with_body((8, 10, 12))
    assert white_body_gains(img, [c]) is None
    assert white_body_gains(img, []) is None


def test_candidates_of_the_second_search_are_added_once():
    a, b, c = cand(10), cand(60), cand(62)  # c is b found again, two pixels over
    assert merge_candidates([a], [b, c], 8) == [a, b]
    assert merge_candidates([a, b], [c], 8) == [a, b]
    assert merge_candidates([a], [b], 1) == [a]


def test_one_landmark_whose_bands_the_two_searches_place_rows_apart_is_added_once():
    a = cand(14, y=224, w=16, band=8, white=20)  # red 224-232, blue 252-260
    b = Candidate((14, 230, 14, 6), (14, 252, 14, 6), 16.0, False, False, False, False, 1.0)  # red boxes share 2 rows
    assert merge_candidates([a], [b], 8) == [a]


def test_of_one_landmark_found_twice_the_taller_white_body_stays():
    whole = cand(398, y=232, w=14, band=6, white=18)
    piece = Candidate((402, 234, 8, 4), (402, 248, 8, 6), 10.0, False, True, False, False, 1.0)  # mast in front
    assert merge_candidates([piece], [whole], 8) == [whole]
    assert merge_candidates([whole], [piece], 8) == [whole]
    assert merge_candidates([whole], [cand(399, y=232, w=14, band=6, white=19)], 8) == [whole]  # alike: the first


def test_a_nearer_landmark_replaces_every_piece_of_it_the_first_search_found():
    # rooms 10113 frame 48: the near landmark (0.2 m) under the camera's balance; under grey-world
    # only its robot's plate over the bumper and a speck in its body, two pieces within its place
    whole = cand(126, y=146, w=116, band=52, white=140)
    plate = Candidate((126, 292, 22, 12), (126, 338, 22, 12), 34.0, False, False, True, True, 1.0)
    speck = cand(212, y=332, w=4, band=2, white=6)
    other = cand(462, y=208, w=34, band=14, white=38)
    assert merge_candidates([other, plate, speck], [whole], 8) == [other, whole]
    # ... but not one that is not clearly taller than each of them
    alike = Candidate((126, 150, 116, 50), (126, 334, 116, 50), 134.0, False, False, False, False, 1.0)
    assert merge_candidates([alike, speck], [whole], 8) == [alike, speck]


def test_pieces_of_one_body_found_as_several_all_give_way_to_the_whole():
    # a cast turned half the white body blue under one balance: two slivers of red-white-blue at its middle
    whole = cand(236, y=210, w=38, band=18, white=50)
    pieces = [Candidate((256, 226, 4, 2), (256, 234, 4, 2), 6.0, True, True, True, True, 1.0),
              Candidate((238, 226, 4, 2), (238, 232, 4, 2), 4.0, True, True, True, True, 1.0)]
    other = cand(400)
    assert merge_candidates([*pieces, other], [whole], 8) == [whole, other]
    alike = cand(238, y=210, w=36, band=18, white=46)  # as tall as the whole: the first stays
    assert merge_candidates([whole], [alike], 8) == [whole]


def test_landmarks_side_by_side_or_one_on_its_robot_are_not_one():
    a = cand(10, w=20)
    assert merge_candidates([a], [cand(31, w=20)], 8) == [a, cand(31, w=20)]  # the next one along
    below = cand(12, y=90, w=16)  # starts below a's blue band: the robot under it, other rows
    assert merge_candidates([a], [below], 8) == [a, below]


def test_the_camera_balance_is_searched_too_when_grey_world_pulls_far_from_one():
    img, c = frame_with_body((150, 150, 150))
    seen = []

    def find(gains):
        seen.append(gains)
        return [c] if near_unit(gains) else []  # found only under the camera's own balance

    cands, gains = balanced_search(find, img, (1.45, 1.29, 0.60), 8)
    assert cands == [c] and seen[:2] == [(1.45, 1.29, 0.60), (1.0, 1.0, 1.0)]
    assert gains == pytest.approx((1.0, 1.0, 1.0), abs=0.01)  # the body is grey: measured without a cast
    seen.clear()
    cands, gains = balanced_search(find, img, (1.01, 1.0, 0.99), 8)
    assert cands == [c] and len(seen) == 1  # near one: one search


def bands(x, y, spacing=40.0, w=20):
    from rangebearing.core.detect import BandCentroids

    box_r, box_b = (x - w // 2, int(y) - 5, w, 10), (x - w // 2, int(y + spacing) - 5, w, 10)
    return BandCentroids((x, y), (x, y + spacing), box_r, box_b, 100.0, 100.0, 50.0, 50.0)


def test_a_landmark_wholly_below_another_of_its_size_is_the_robot_under_it():
    from rangebearing.core.stacked import drop_stacked

    top, plate = bands(100, 50), bands(110, 110)  # the robot's red plate, bumper and blue floor below
    assert drop_stacked([top, plate]) == [top]
    beside = bands(160, 50)  # a neighbour at one range, on the same rows
    assert drop_stacked([top, beside]) == [top, beside]
    nearer_below = bands(100, 110, spacing=80.0)  # a nearer landmark lower in the image: real
    assert drop_stacked([top, nearer_below]) == [top, nearer_below]
    far_away = bands(400, 110)  # same size, lower, but far across the image (a tilted horizon)
    assert drop_stacked([top, far_away]) == [top, far_away]
    smaller_below = bands(104, 100, spacing=16.0)  # a small fragment on the robot's body under it
    assert drop_stacked([top, smaller_below]) == [top]


def test_nothing_farther_shows_inside_a_nearer_landmarks_silhouette():
    from rangebearing.core.stacked import drop_stacked

    near = bands(100, 50, spacing=60.0, w=30)  # rows 45-115, columns 85-115
    # its red band's top over its body over its own camera board, read as a far landmark
    inside = bands(100, 48, spacing=24.0, w=8)
    assert drop_stacked([near, inside]) == [near]
    # a farther landmark partly hidden beside it shows outside its silhouette: real
    beside = bands(120, 60, spacing=30.0, w=10)
    assert drop_stacked([near, beside]) == [near, beside]
    # one of about its size overlapping it is a touching neighbour, not a part of it
    neighbour = bands(110, 52, spacing=55.0, w=30)
    assert drop_stacked([near, neighbour]) == [near, neighbour]


def test_under_a_strong_cast_half_the_correction_is_searched_too():
    img, c = frame_with_body((150, 150, 150))
    grey = (0.71, 1.13, 1.35)  # a blue room: grey-world makes the wall grey and the white bodies orange
    seen = []

    def find(gains):  # the landmark shows only halfway: the wall out of the blue class, the body still white
        seen.append(gains)
        return [c] if all(abs(g - h) < 0.01 for g, h in zip(gains, halfway(grey))) else []

    cands, _ = balanced_search(find, img, grey, 8)
    assert cands == [c] and seen == [grey, (1.0, 1.0, 1.0), halfway(grey)]
    assert halfway((4.0, 1.0, 0.25)) == (2.0, 1.0, 0.5)
    seen.clear()
    balanced_search(find, img, (1.1, 1.0, 0.92), 8)  # a mild cast: grey-world and the camera's balance only
    assert len(seen) == 2


def test_other_balances_are_not_searched_when_the_first_found_landmarks_explaining_all_it_saw():
    from rangebearing.core.structure import Found

    img, c = frame_with_body((150, 150, 150))
    seen = []

    def find(all_explained, landmarks):
        def run(gains):
            seen.append(gains)
            return Found(landmarks, lambda: all_explained)
        return run

    grey = (0.71, 1.13, 1.35)  # a strong cast: three balances would be searched
    cands, _ = balanced_search(find(True, [c]), img, grey, 8)
    assert cands == [c] and seen == [grey]
    seen.clear()
    balanced_search(find(False, [c]), img, grey, 8)  # something of a band's colour is unexplained
    assert seen == [grey, (1.0, 1.0, 1.0), halfway(grey)]
    seen.clear()
    balanced_search(find(True, []), img, grey, 8)  # nothing found: every balance, as before
    assert len(seen) == 3


def test_the_second_look_adds_only_landmarks_apart_from_those_found():
    found = [cand(20)]
    apart, touching, striped = cand(100), cand(32), cand(60)
    striped = dataclasses.replace(striped, cut_left=True, cut_right=True)  # stripes run on beyond both sides
    one_side = dataclasses.replace(cand(130), cut_left=True)  # a real landmark beside a neighbour
    assert second_look(found, [touching, apart, striped, one_side]) == [apart, one_side]
    # before a wall of its blue band's colour: cut on both sides, but its red band ends at both limbs
    walled = dataclasses.replace(striped, band_ends=(True, True))
    assert second_look(found, [walled, dataclasses.replace(walled, band_ends=(True, False))]) == [walled]
    assert second_look([], [dataclasses.replace(walled, red_bbox_px=(0, 40, 20, 8))], 160) == []  # frame's edge
    assert second_look(found, [dataclasses.replace(walled, visible=0.75)]) == []  # narrower than its limbs


def test_the_second_look_drops_every_piece_of_a_split_run_when_one_shows_no_limb():
    # a fat can's run split into three silhouettes: same rows, side by side, cut where they meet
    row = [dataclasses.replace(cand(x), cut_left=x > 40, cut_right=x < 80) for x in (40, 60, 80)]
    assert second_look([], row) == []
    # a landmark cut on one side where it meets the run's end (other rows: another run) stays, as does one
    # of the same rows apart from it
    beside, apart = dataclasses.replace(cand(100, y=42), cut_left=True), dataclasses.replace(cand(130), cut_left=True)
    assert second_look([], [*row, beside, apart]) == [beside, apart]
    assert second_look([], row[:1] + row[2:]) == row[:1] + row[2:]  # the ends alone: each with a limb


def test_the_second_look_takes_the_frames_edge_for_a_cut_side():
    # photoreal-crowd 19032 frame 15: an orange wall over a white one over a dark box, cut out of the frame's
    # left edge and cut on its right: it shows no limb, as a stripe between two cuts does
    at_edge = dataclasses.replace(cand(0, w=50), cut_right=True)
    whole_at_edge = cand(0, w=50)  # a limb on its right: a landmark coming into view
    right_edge = dataclasses.replace(cand(110, w=50), cut_left=True)  # out of a 160-pixel frame's right edge
    assert second_look([], [at_edge, whole_at_edge, right_edge], 160) == [whole_at_edge]
    assert second_look([], [at_edge, whole_at_edge, right_edge]) == [at_edge, whole_at_edge, right_edge]


def test_the_second_look_changes_neither_the_landmarks_found_nor_their_gains():
    img, c = frame_with_body((120, 160, 200))
    far = cand(120, w=10, band=4, white=12)
    plain = balanced_search(lambda g: [c], img, (1.0, 1.0, 1.0), 8)
    seen = []

    def relaxed(gains, boxes):
        seen.append(boxes)
        return [dataclasses.replace(c, white_px=30.0), far]  # c's rims moved by the lower floors: not taken

    more = balanced_search(lambda g: [c], img, (1.0, 1.0, 1.0), 8, relaxed=relaxed)
    assert more[0] == [c, far] and more[1] == plain[1]  # the same c, measured with the same gains
    assert seen == [[(60, 40, 80, 80)]]  # blind where c is: its box from red top to blue bottom
    assert balanced_search(lambda g: [c], img, (1.0, 1.0, 1.0), 1, relaxed=lambda g, boxes: [far])[0] == [c]  # the cap


def test_a_frame_two_and_a_half_stops_under_is_found_by_the_second_look():
    from rangebearing import Pipeline, load_config
    from rangebearing.core.detect import downscale, search_candidates
    from rangebearing.synth import Imaging, LandmarkPose, Scene, render

    params = load_config(None).pipeline
    sc = Scene(landmarks=(LandmarkPose(0.9, 0.05),), imaging=Imaging(blur_sigma_px=0.6, read_noise=0.004,
                                                                      shot_noise=0.0006), wall_distance_m=2.5)
    img = render(sc, np.random.default_rng(3))
    dark = np.round(img * 0.15).astype(np.uint8)  # white body at V ~34, bands at V ~15-25
    small = downscale(dark, 2)
    det, geometry = params.detection, params.landmark
    assert search_candidates(small, det, (1.0, 1.0, 1.0), 3, geometry).candidates == []  # under the floors
    assert len(search_candidates(small, det, (1.0, 1.0, 1.0), 3, geometry, relaxed=[]).candidates) == 1
    (lm,) = Pipeline(params, track=False).process(dark).landmarks
    assert lm.range_m == pytest.approx(0.9, rel=0.01)
    assert abs(lm.bearing_rad - 0.05) < math.radians(0.15)


def test_a_cut_side_of_a_nearer_landmark_hides_its_whole_silhouette():
    import dataclasses

    from rangebearing.core.stacked import drop_stacked
    from rangebearing.core.structure import Candidate

    # a near landmark (spacing 110: 70 px wide, columns 65-135) whose left part a mast in front hides:
    # its run and box start at column 100, but its axis is still at 100
    near = bands(100, 50, spacing=110.0, w=70)
    box_r, box_b = (100, 45, 35, 10), (100, 155, 35, 10)
    cut = Candidate(box_r, box_b, 80.0, False, False, True, False, 0.5)
    near = dataclasses.replace(near, red_bbox_px=box_r, blue_bbox_px=box_b, candidate=cut)
    # the mast under its camera board before its body, read as a far landmark left of its box
    behind = bands(90, 80, spacing=20.0, w=8)
    assert drop_stacked([near, behind]) == [near]
    # seen whole (not cut), the same box hides nothing left of it
    whole = dataclasses.replace(near, candidate=dataclasses.replace(cut, cut_left=False))
    assert drop_stacked([whole, behind]) == [whole, behind]
