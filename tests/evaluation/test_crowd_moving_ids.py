"""Acceptance of issue 8's id target on a short ``crowd-moving`` sequence (the full 300-frame figure is
measured with ``replay --track --truth``; see docs/tracking.md).

40 frames (1.3 s at 30 fps, full 640×480: at lower resolutions the readings of
far robots are too poor to say anything about ids) of 4-6 robots driving about
and crossing each other: at most 1 id switch per 1,000 matched landmark-frames,
so none here, and every robot that reappears within 15 frames keeps its id.
"""

from __future__ import annotations

from rangebearing.core.params import PipelineParams
from rangebearing.core.pipeline import Pipeline
from rangebearing.core.types import CameraIntrinsics
from rangebearing.evaluation.identity import id_report
from rangebearing.synth.dataset import generate

CAMERA = CameraIntrinsics()


SEED = 6  # a sequence with robots lost and back within 15 frames, so the return is tested (seed 3,
#          used before, has no such gap with today's detector and tracker)


def test_a_moving_crowd_keeps_its_ids():
    pipe = Pipeline(PipelineParams(camera=CAMERA), track=True)
    frames = [(pipe.process(image, t_s=i / 30.0).landmarks, rows)
              for i, (_, image, rows) in enumerate(generate(40, SEED, "crowd-moving", camera=CAMERA))]
    rep = id_report(frames)
    assert rep.robots >= 4 and rep.landmark_frames >= 100, rep
    assert rep.switches_per_1000 <= 1.0, rep
    assert rep.returns >= 1 and rep.returns_kept == rep.returns, rep
    assert rep.untracked == 0
