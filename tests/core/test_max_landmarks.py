"""A crowd larger than one datagram holds is still detected and tracked whole; the wire sends what fits.

``detection.max_landmarks`` (16 by default) bounds the search, not the packet:
12 neighbours side by side are all found and each gets its own track id,
and the datagram carries the nearest that fit with ``omitted`` counting the rest.
"""

from __future__ import annotations

import math

import numpy as np

from rangebearing import Pipeline, load_config
from rangebearing.net.fit import MTU_PAYLOAD_BYTES, encode_fitting, landmarks_that_fit
from rangebearing.net.protocol import decode_reading
from rangebearing.synth import Imaging, LandmarkPose, Scene, render

NOISE = Imaging(blur_sigma_px=0.5, read_noise=0.004, shot_noise=0.0005)


def _crowd(n: int, frame: int, rng: np.random.Generator) -> np.ndarray:
    bearings = np.linspace(-0.40, 0.40, n)
    sway = 0.01 * math.sin(frame / 3.0)
    lms = tuple(LandmarkPose(0.5 if k % 2 else 1.2, float(b) + sway) for k, b in enumerate(bearings))
    return render(Scene(landmarks=lms, wall_distance_m=2.5, imaging=NOISE), rng)


def test_twelve_neighbours_are_all_detected_tracked_and_the_datagram_carries_what_fits():
    cfg = load_config(None)
    assert cfg.detection.max_landmarks >= 16 > landmarks_that_fit(cfg.publish.robot_id)
    pipe = Pipeline(cfg.pipeline, track=True)
    rng = np.random.default_rng(4)
    for i in range(3):
        lms = pipe.process(_crowd(12, i, rng), t_s=i / 30.0).landmarks
        assert len(lms) == 12
        assert len({lm.track_id for lm in lms}) == 12 and min(lm.track_id for lm in lms) == 0
    assert max(lm.track_id for lm in lms) == 11  # the same 12 tracks on every frame
    data = encode_fitting(cfg.publish.robot_id, 2, 0.066, lms, 30.0, 0)
    got = decode_reading(data)
    assert len(data) <= MTU_PAYLOAD_BYTES and got.omitted == 12 - len(got.landmarks) > 0
    nearest = sorted(lms, key=lambda lm: lm.range_m)[: len(got.landmarks)]
    assert sorted(lm.track_id for lm in got.landmarks) == sorted(lm.track_id for lm in nearest)
