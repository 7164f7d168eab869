"""A landmark coming in at the frame's sides is scanned for as it comes in, not at the next scheduled scan."""

from __future__ import annotations

from typing import Any, Callable, Tuple

import numpy as np

from rangebearing import Pipeline, load_config
from rangebearing.core.newcomers import EDGE_STRIP_PX, NEW_COLUMNS, came_in, side_colour
from rangebearing.core.params import DetectionParams
from rangebearing.synth import Imaging, LandmarkPose, Scene, render

RED, BLUE, GREY = (40, 40, 200), (200, 60, 40), (128, 128, 128)  # BGR
UNIT = (1.0, 1.0, 1.0)


def frame(w: int = 160, h: int = 120) -> np.ndarray:
    return np.full((h, w, 3), GREY, np.uint8)


def paint_landmark(img: np.ndarray, x0: int, x1: int) -> None:
    img[20:30, x0:x1] = RED
    img[30:60, x0:x1] = (230, 230, 230)
    img[60:70, x0:x1] = BLUE


def test_red_over_blue_columns_are_counted_on_their_side():
    img = frame()
    paint_landmark(img, 0, 10)  # 5 half-resolution columns on the left
    assert side_colour(img, DetectionParams(), UNIT, []) == (5, 0)
    paint_landmark(img, 150, 160)
    assert side_colour(img, DetectionParams(), UNIT, []) == (5, 5)


def test_a_known_landmark_is_blanked_and_walls_of_one_colour_count_nothing():
    img = frame()
    paint_landmark(img, 0, 10)
    assert side_colour(img, DetectionParams(), UNIT, [(0, 15, 12, 60)]) == (0, 0)
    wall = frame()
    wall[:, :, :] = BLUE  # a blue wall, then a red one: neither holds both colours
    assert side_colour(wall, DetectionParams(), UNIT, []) == (0, 0)
    wall[:60] = RED
    wall[60:] = GREY
    assert side_colour(wall, DetectionParams(), UNIT, []) == (0, 0)


def test_only_growth_past_the_recorded_counts_is_a_newcomer():
    assert not came_in((7, 3), (7, 3))
    assert not came_in((7 + NEW_COLUMNS - 1, 3), (7, 3))
    assert came_in((7, 3 + NEW_COLUMNS), (7, 3))
    assert not came_in((0, 0), (9, 9))  # something went out: nothing new to find


def test_the_strips_are_the_frame_sides_only():
    img = frame()
    paint_landmark(img, EDGE_STRIP_PX + 4, EDGE_STRIP_PX + 14)  # inside the frame, beyond the left strip
    assert side_colour(img, DetectionParams(), UNIT, []) == (0, 0)


def late_frames(poses: Callable[[int], Tuple[LandmarkPose, ...]], n: int, seed: int) -> Tuple[int, Any]:
    """Frames (after the first) in which a tracker reports fewer landmarks than a full scan, over ``n`` noisy
    renders of ``poses(i)`` before a wall 2.5 m away; and the last frame's full-scan result."""
    rng = np.random.default_rng(seed)
    noise = Imaging(blur_sigma_px=0.5, read_noise=0.004, shot_noise=0.0005)
    cfg = load_config(None)
    full, tracker = Pipeline(cfg.pipeline, track=False), Pipeline(cfg.pipeline, track=True)
    late, a = 0, None
    for k in range(n):
        img = render(Scene(landmarks=poses(k), wall_distance_m=2.5, imaging=noise), rng)
        a, b = full.process(img), tracker.process(img)
        if k > 0 and len(b.landmarks) < len(a.landmarks):
            late += 1
    return late, a


def test_a_landmark_driving_in_at_the_side_is_found_as_soon_as_a_full_scan_finds_it():
    # a still landmark in the middle keeps the tracker in window mode; a second one comes in from the left edge
    late, _ = late_frames(lambda i: (LandmarkPose(0.8, -0.1), LandmarkPose(1.0, 0.50 - 0.006 * i)), 16, seed=5)
    # a full scan every 8 frames alone would leave it unreported for several frames after it came in
    assert late <= 1


def test_the_counts_are_classified_again_only_when_the_strips_change():
    from rangebearing.core.newcomers import PROBE_CHANGE, side_view

    cfg = DetectionParams()
    img = frame()
    paint_landmark(img, 0, 10)
    first = side_view(img, cfg, UNIT, [])
    assert first.counts == (5, 0)
    rng = np.random.default_rng(0)
    noisy = np.clip(img.astype(int) + rng.integers(-PROBE_CHANGE // 2, PROBE_CHANGE // 2 + 1, img.shape), 0, 255)
    assert side_view(noisy.astype(np.uint8), cfg, UNIT, [], first) is first  # camera noise: the same counts
    grown = img.copy()
    paint_landmark(grown, 150, 160)  # something came in on the right
    assert side_view(grown, cfg, UNIT, [], first).counts == (5, 5)
    assert side_view(img, cfg, UNIT, [(0, 15, 12, 60)], first).counts == (0, 0)  # blanked otherwise: counted again
    assert side_view(img, cfg, (1.2, 1.0, 0.8), [], first) is not first  # other gains classify otherwise


def test_a_change_between_the_probe_rows_of_a_landmark_is_seen():
    # the smallest thing that can come in, a far landmark alone (no robot below it), crosses probe rows
    from rangebearing.core.newcomers import PROBE_STEP, side_view

    cfg = DetectionParams()
    img = frame(160, 240)
    first = side_view(img, cfg, UNIT, [])
    for top in range(0, 2 * PROBE_STEP):  # 15 mm bands over a 40 mm body: 20 rows at 2.2 m (fy 634 px)
        far = img.copy()
        far[100 + top : 104 + top, 150:160] = RED
        far[104 + top : 116 + top, 150:160] = (230, 230, 230)
        far[116 + top : 120 + top, 150:160] = BLUE
        assert side_view(far, cfg, UNIT, [], first).counts == (0, 5)
