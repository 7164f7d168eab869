import dataclasses
import math
import re

import numpy as np
import pytest

from rangebearing import Config, FrameError, Pipeline, load_config
from rangebearing.synth import LandmarkPose, Scene, render

SCENE = Scene(landmarks=(LandmarkPose(0.4, 0.1),), wall_distance_m=2.0)


@pytest.mark.parametrize(
    "frame, message",
    [
        (None, "not a numpy array"),
        (np.zeros((480, 640), np.uint8), "expected (height, width, 3)"),
        (np.zeros((480, 640, 3), np.float32), "dtype float32"),
        (np.zeros((4, 4, 3), np.uint8), "too small"),
        (np.zeros((720, 1280, 3), np.uint8), "another aspect ratio"),
    ],
)
def test_unusable_frames_raise_frame_error(frame, message):
    with pytest.raises(FrameError, match=re.escape(message)):
        Pipeline(load_config(None).pipeline).process(frame)


def test_an_empty_scene_gives_no_landmarks():
    assert Pipeline(load_config(None).pipeline).process(render(Scene(wall_distance_m=2.0))).landmarks == ()


def test_a_smaller_frame_of_the_same_camera_reads_the_same():
    img = render(SCENE)
    small = img.reshape(240, 2, 320, 2, 3).mean(axis=(1, 3)).round().astype(np.uint8)
    a = Pipeline(load_config(None).pipeline).process(img).landmarks[0]
    b = Pipeline(load_config(None).pipeline).process(small).landmarks[0]
    assert b.range_m == pytest.approx(a.range_m, rel=0.01)
    assert b.bearing_rad == pytest.approx(a.bearing_rad, abs=0.002)


def test_a_change_of_frame_size_mid_run_starts_the_tracks_again_with_new_ids():
    import cv2

    img = render(SCENE)
    pipe = Pipeline(load_config(None).pipeline, track=True)
    first = pipe.process(img).landmarks
    assert pipe.process(img).tracked  # the second frame follows the landmark
    for size in ((80, 60), (1280, 960), (640, 480)):  # tracks of another size would point outside the frame
        got = pipe.process(cv2.resize(img, size, interpolation=cv2.INTER_AREA))
        assert not got.tracked
    again = pipe.process(img).landmarks
    assert again[0].range_m == pytest.approx(first[0].range_m, rel=0.01)
    assert again[0].track_id > first[0].track_id  # ids are never reused


def test_readings_with_no_positive_range_are_dropped():
    cfg = load_config(None)
    broken = dataclasses.replace(cfg, model=dataclasses.replace(cfg.model, c_m=-0.5))
    assert Pipeline(cfg.pipeline).process(render(SCENE)).landmarks[0].range_m == pytest.approx(0.4, rel=0.01)
    assert Pipeline(broken.pipeline).process(render(SCENE)).landmarks == ()


def test_the_paper_method_finds_one_landmark_with_its_own_model():
    cfg = load_config(None)
    paper = dataclasses.replace(
        cfg,
        detection=dataclasses.replace(cfg.detection, method="paper"),
        model=dataclasses.replace(cfg.model, kind="paper"),
    )
    (lm,) = Pipeline(paper.pipeline).process(render(SCENE)).landmarks
    assert lm.range_m == pytest.approx(0.4, rel=0.1)  # the paper's k = 35 px·m, uncalibrated
    assert lm.bearing_rad > 0


@pytest.mark.parametrize("preset", ["multi", "clutter", "wide", "crowd", "touching"])
def test_the_yuv_search_reads_what_the_bgr_search_reads(preset):
    """Search on the chroma planes of OpenCV's I420, measure on BGR: the readings of the BGR path."""
    from rangebearing.core.yuv import yuv420_from_bgr
    from rangebearing.synth import random_scene

    rng = np.random.default_rng(41)
    params = Config().pipeline
    compared = 0
    for _ in range(4):
        bgr = render(random_scene(rng, preset), rng)
        want = Pipeline(params, track=False).process(bgr).landmarks
        got = Pipeline(params, track=False).process(bgr, search=yuv420_from_bgr(bgr)).landmarks
        assert len(got) == len(want)
        for g, w in zip(got, want):
            assert g.range_m == pytest.approx(w.range_m, rel=0.002)
            assert abs(g.bearing_rad - w.bearing_rad) <= math.radians(0.02)
            compared += 1
    assert compared >= (1 if preset == "clutter" else 3)
