"""Invariance of the band centroids, in the style of scikit-image's moment tests.

A landmark drawn by hand (flat colours, no renderer) is shifted by k pixels;
its band centroids must move by exactly k, also for odd k, which moves the
landmark across the ½-downscaling grid the search runs on. Bands tall enough to
be measured on the ¼ or ⅛ pyramid level move exactly with shifts that are
multiples of that level.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rangebearing.core import detect
from rangebearing.core.params import DetectionParams, PipelineParams
from rangebearing.core.pipeline import Pipeline

GREY, WHITE, RED, BLUE, DARK = (120, 120, 120), (215, 215, 215), (40, 35, 190), (185, 60, 30), (25, 25, 25)


@pytest.fixture
def raw_moments(monkeypatch):
    """The bands' moments as measured: the outline correction (:func:`.limbs.moments_outline`, tested in
    test_measure.py) moves a column by a share of its distance from the frame's centre, by design."""
    monkeypatch.setattr(detect, "moments_outline", lambda x_px, *_: x_px)


def landmark_sprite(width_px: int) -> np.ndarray:
    """A front view of the landmark, ``width_px`` wide, on a grey margin (BGR uint8)."""
    s = width_px / 35.0  # pixels per millimetre
    band, height = round(15 * s), round(70 * s)
    sprite = np.full((height + 10, width_px + 6, 3), GREY, np.uint8)
    body = sprite[2 : 2 + height, 3 : 3 + width_px]
    body[:] = WHITE
    body[:band] = RED
    body[height - band :] = BLUE
    sprite[2 + height :] = DARK  # the robot under the landmark
    return sprite


def frame_with(sprite: np.ndarray, x: int, y: int, size=(480, 640)) -> np.ndarray:
    frame = np.full((*size, 3), GREY, np.uint8)
    h, w = sprite.shape[:2]
    frame[y : y + h, x : x + w] = sprite
    return frame


PARAMS = PipelineParams(detection=dataclasses.replace(DetectionParams(), white_balance="none"))


def centroids(frame: np.ndarray) -> np.ndarray:
    (lm,) = Pipeline(PARAMS, track=False).process(frame).landmarks
    return np.array([*lm.red_xy_px, *lm.blue_xy_px])


@pytest.mark.usefixtures("raw_moments")
@pytest.mark.parametrize("dx, dy", [(1, 0), (0, 1), (1, 1), (3, 0), (0, 3), (2, 5), (-1, -3)])
def test_a_small_landmark_moves_exactly_with_the_image(dx: int, dy: int) -> None:
    sprite = landmark_sprite(22)
    before = centroids(frame_with(sprite, 300, 200))
    after = centroids(frame_with(sprite, 300 + dx, 200 + dy))
    assert after - before == pytest.approx([dx, dy, dx, dy], abs=1e-4)


@pytest.mark.usefixtures("raw_moments")
@pytest.mark.parametrize("k", [8, 16])
def test_a_tall_landmark_moves_exactly_by_multiples_of_its_pyramid_level(k: int) -> None:
    sprite = landmark_sprite(110)
    before = centroids(frame_with(sprite, 200, 80))
    after = centroids(frame_with(sprite, 200 + k, 80 + k))
    assert after - before == pytest.approx([k, k, k, k], abs=1e-3)


def test_the_band_centroids_sit_at_the_band_centres_drawn() -> None:
    sprite = landmark_sprite(22)
    got = centroids(frame_with(sprite, 300, 200))
    band = round(15 * 22 / 35)
    height = round(70 * 22 / 35)
    x_centre = 300 + 3 + (22 - 1) / 2
    red_y = 200 + 2 + (band - 1) / 2
    blue_y = 200 + 2 + height - band + (band - 1) / 2
    assert got == pytest.approx([x_centre, red_y, x_centre, blue_y], abs=0.05)


def test_mirroring_the_image_mirrors_the_bearing() -> None:
    sprite = landmark_sprite(22)
    frame = frame_with(sprite, 150, 200)
    pipe = Pipeline(PARAMS, track=False)
    (a,) = pipe.process(frame).landmarks
    # mirror about the principal point (cx = 319.5): column c goes to 639 - c
    (b,) = pipe.process(np.ascontiguousarray(frame[:, ::-1])).landmarks
    assert b.bearing_rad == pytest.approx(-a.bearing_rad, abs=1e-6)
    assert b.range_m == pytest.approx(a.range_m, rel=1e-6)
