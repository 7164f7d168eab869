"""The search range: far landmarks are found whatever the calibrated envelope, nothing is read past MAX_RANGE_M."""

import dataclasses

import numpy as np
import pytest

from rangebearing import Pipeline, load_config
from rangebearing.core.pipeline import MAX_RANGE_M
from rangebearing.synth import Imaging, LandmarkPose, Scene, render


@pytest.fixture(scope="module")
def frame():
    scene = Scene(landmarks=(LandmarkPose(1.0, 0.05),), imaging=Imaging(blur_sigma_px=0.6, read_noise=0.003),
                  wall_distance_m=2.5)
    return render(scene, np.random.default_rng(5))


def test_a_reading_past_the_search_range_is_dropped(frame):
    cfg = load_config(None).pipeline
    (lm,) = Pipeline(cfg, track=False).process(frame).landmarks
    assert lm.range_m == pytest.approx(1.0, rel=0.01)
    # the same pixels read through a model that puts them 3x farther: past MAX_RANGE_M, no reading
    far = dataclasses.replace(cfg, model=dataclasses.replace(cfg.model, spacing_m=cfg.model.spacing_m * 3.0))
    assert MAX_RANGE_M < 3.0
    assert Pipeline(far, track=False).process(frame).landmarks == ()
