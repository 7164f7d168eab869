"""The pipeline's track ids: who gets them, and how the counter runs across resets."""

from __future__ import annotations

import numpy as np
import pytest

from rangebearing import Pipeline, load_config
from rangebearing.synth import LandmarkPose, Scene, render


@pytest.fixture(scope="module")
def frame() -> np.ndarray:
    return render(Scene(landmarks=(LandmarkPose(0.4, 0.1), LandmarkPose(0.7, -0.2)), wall_distance_m=2.0))


def _ids(pipe: Pipeline, frame: np.ndarray, t_s=None):
    return sorted(lm.track_id for lm in pipe.process(frame, t_s=t_s).landmarks)


def test_a_sequence_keeps_its_ids_and_gets_rates(frame):
    pipe = Pipeline(load_config(None).pipeline)
    assert pipe.ids and _ids(pipe, frame, 0.0) == [0, 1]
    for k in range(1, 5):
        result = pipe.process(frame, t_s=k / 30.0)
        assert sorted(lm.track_id for lm in result.landmarks) == [0, 1]
    # a still scene: rates near zero once the tracks have three readings
    assert all(lm.range_rate_mps is not None and abs(lm.range_rate_mps) < 0.02 for lm in result.landmarks)
    assert all(abs(lm.bearing_rate_radps) < 0.02 for lm in result.landmarks)
    assert pipe.next_track_id == 2


def test_independent_frames_get_no_ids(frame):
    result = Pipeline(load_config(None).pipeline, track=False).process(frame)
    assert [lm.track_id for lm in result.landmarks] == [-1, -1]
    assert all(lm.range_rate_mps is None and lm.bearing_rate_radps is None for lm in result.landmarks)
    assert _ids(Pipeline(load_config(None).pipeline, track=False, ids=True), frame) == [0, 1]


def test_reset_never_reuses_an_id_unless_a_new_run_starts(frame):
    pipe = Pipeline(load_config(None).pipeline)
    assert _ids(pipe, frame) == [0, 1]
    pipe.reset()
    assert _ids(pipe, frame) == [2, 3]  # forgotten tracks, fresh ids
    pipe.reset(new_run=True)
    assert _ids(pipe, frame) == [0, 1]


def test_a_rebuilt_pipeline_continues_the_count(frame):
    old = Pipeline(load_config(None).pipeline)
    _ids(old, frame)
    new = Pipeline(load_config(None).pipeline, first_track_id=old.next_track_id)  # as the daemon on reload
    assert _ids(new, frame) == [2, 3]
