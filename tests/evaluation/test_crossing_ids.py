"""Rendered robots crossing in bearing keep their track ids through the pipeline (issue 8).

One 45-frame sequence (1.5 s at 30 fps): robot 0 passes in front of robot 1
(different ranges, 0.45 vs 0.95 m) and robots 2 and 3 cross at similar ranges
(0.62-0.74 m), while robot 0 also crosses both. Landmarks hide each other and
merge in the image on the way.
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

from .crossing import CAMERA, CROSSINGS, FPS, crossing_frames

FRAMES = 45


@pytest.fixture(scope="module")
def sequence() -> List[Tuple[float, np.ndarray, List[TruthRow]]]:
    return list(crossing_frames(FRAMES, seed=1))


@pytest.fixture(scope="module")
def results(sequence) -> List[FrameResult]:
    pipe = Pipeline(PipelineParams(camera=CAMERA), track=True)
    return [pipe.process(image, t_s=t) for t, image, _ in sequence]


def test_crossing_robots_keep_their_ids(sequence, results):
    rep = id_report((r.landmarks, truth) for r, (_, _, truth) in zip(results, sequence))
    assert rep.robots >= 3 and rep.landmark_frames >= 100
    assert rep.switches == 0, rep
    assert rep.returns >= 1 and rep.returns_kept == rep.returns, rep


def test_published_rates_follow_the_robots(sequence, results):
    """Robot 0 sweeps 0.62 rad right in 1.5 s: its bearing rate is -0.42 rad/s, its range rate +0.034 m/s."""
    r0, r1, b0, b1 = CROSSINGS[0]
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
