"""Rendered robots crossing in bearing keep their track ids through the pipeline (issue 8).

Two 36-frame sequences (1.2 s at 30 fps), each of two robots sweeping 0.6 rad
across each other: at different ranges (0.45 and 0.95 m: the near one hides
the far one), and at similar ranges (0.62-0.74 m: the landmarks touch and
merge in the image).
"""

from __future__ import annotations

import math
from typing import List, Tuple

import numpy as np
import pytest

from rangebearing.core.params import PipelineParams
from rangebearing.core.pipeline import Pipeline
from rangebearing.core.types import FrameResult
from rangebearing.evaluation.identity import id_report, match_identities
from rangebearing.evaluation.truth import TruthRow

from .crossing import APART, CAMERA, CLOSE, FPS, crossing_frames

FRAMES = 36
Sequence = List[Tuple[float, np.ndarray, List[TruthRow]]]


def _run(sequence: Sequence) -> List[FrameResult]:
    pipe = Pipeline(PipelineParams(camera=CAMERA), track=True)
    return [pipe.process(image, t_s=t) for t, image, _ in sequence]


@pytest.fixture(scope="module")
def sequence() -> Sequence:
    return list(crossing_frames(FRAMES, seed=1, paths=APART))


@pytest.fixture(scope="module")
def results(sequence) -> List[FrameResult]:
    return _run(sequence)


def test_robots_crossing_at_different_ranges_keep_their_ids(sequence, results):
    rep = id_report((r.landmarks, truth) for r, (_, _, truth) in zip(results, sequence))
    assert rep.robots == 2 and rep.landmark_frames >= 55, rep
    assert rep.switches == 0, rep
    assert rep.returns >= 1 and rep.returns_kept == rep.returns, rep  # the far one came back from behind


def test_robots_crossing_at_similar_ranges_keep_their_ids():
    sequence = list(crossing_frames(FRAMES, seed=2, paths=CLOSE))
    results = _run(sequence)
    rep = id_report((r.landmarks, truth) for r, (_, _, truth) in zip(results, sequence))
    assert rep.robots == 2 and rep.landmark_frames >= 55, rep
    assert rep.switches == 0 and rep.returns_kept == rep.returns, rep


def test_published_rates_follow_the_robots(sequence, results):
    """Robot 0 sweeps 0.6 rad right in 1.2 s: its bearing rate is -0.51 rad/s, its range rate +0.043 m/s."""
    r0, r1, b0, b1 = APART[0]
    duration = (FRAMES - 1) / FPS
    rates = []
    for result, (_, _, truth) in list(zip(results, sequence))[-15:]:
        for t, lm in match_identities(result.landmarks, truth):
            if t.robot == 0 and lm.bearing_rate_radps is not None:
                rates.append((lm.range_rate_mps, lm.bearing_rate_radps))
    assert len(rates) >= 10
    rr, br = np.median(np.array(rates), axis=0)
    assert br == pytest.approx((b1 - b0) / duration, abs=0.06)
    assert rr == pytest.approx((r1 - r0) / duration, abs=0.05)


def test_ids_leave_the_raw_measurement_alone(sequence, results):
    plain = Pipeline(PipelineParams(camera=CAMERA), track=True, ids=False)
    for (t, image, _), with_ids in zip(sequence[:10], results[:10]):
        got = plain.process(image, t_s=t).landmarks
        assert [(lm.range_m, lm.bearing_rad) for lm in got] == [(lm.range_m, lm.bearing_rad)
                                                                for lm in with_ids.landmarks]
        assert all(lm.track_id == -1 and lm.range_rate_mps is None for lm in got)
        assert all(lm.track_id >= 0 for lm in with_ids.landmarks)
    assert not math.isnan(results[-1].landmarks[0].range_m)
