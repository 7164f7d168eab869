"""Hostile but well-formed frames never break the detector: edges, sizes, flips, gamma, noise, JPEG, blur.

A small seeded fuzz over rendered crowds: every frame either gives readings or a
clear :class:`FrameError`; no other exception escapes ``Pipeline.process``, with
tracking on (frames of changing size and content follow each other) and off.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from rangebearing import Config, FrameError, Pipeline
from rangebearing.synth.dataset import generate

SIZES = ((64, 48), (80, 60), (160, 120), (320, 240), (800, 600))


def _hostile(im: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    h, w = im.shape[:2]
    k = int(rng.integers(0, 8))
    if k == 0:  # landmarks across the frame's edges, the rest filled flat, replicated or mirrored
        m = np.float32([[1, 0, rng.integers(-w // 2, w // 2)], [0, 1, rng.integers(-h // 2, h // 2)]])
        border = int(rng.choice([cv2.BORDER_CONSTANT, cv2.BORDER_REPLICATE, cv2.BORDER_REFLECT]))
        fill = tuple(int(v) for v in rng.integers(0, 256, 3))
        return cv2.warpAffine(im, m, (w, h), borderMode=border, borderValue=fill)
    if k == 1:
        return cv2.resize(im, SIZES[int(rng.integers(len(SIZES)))], interpolation=cv2.INTER_AREA)
    if k == 2:
        return np.ascontiguousarray(im[::-1] if rng.random() < 0.5 else im[:, ::-1])
    if k == 3:
        return (255 * (im / 255.0) ** rng.uniform(0.3, 3.0)).astype(np.uint8)
    if k == 4:
        _, buf = cv2.imencode(".jpg", im, [cv2.IMWRITE_JPEG_QUALITY, int(rng.integers(2, 30))])
        return cv2.imdecode(buf, cv2.IMREAD_COLOR)
    if k == 5:  # salt of random colours
        out = im.copy()
        hit = rng.random((h, w)) < rng.uniform(0.001, 0.2)
        out[hit] = rng.integers(0, 256, (int(hit.sum()), 3))
        return out
    if k == 6:
        return np.clip(im * rng.uniform(0.1, 4.0) + rng.uniform(-100, 100), 0, 255).astype(np.uint8)
    return np.ascontiguousarray(im[:, :, rng.permutation(3)])


@pytest.mark.parametrize("preset, track", [("crowd", True), ("touching", False), ("occlusion", True)])
def test_no_exception_but_frame_error_escapes_the_detector(preset, track):
    rng = np.random.default_rng(77)
    pipe = Pipeline(Config().pipeline, track=track)
    done = 0
    for _, image, _ in generate(6, 4100, preset):
        for _ in range(4):
            frame = _hostile(_hostile(image, rng), rng) if rng.random() < 0.3 else _hostile(image, rng)
            try:
                result = pipe.process(frame)
            except FrameError:
                continue
            done += 1
            assert all(lm.range_m > 0 and np.isfinite(lm.bearing_rad) and lm.range_sigma_m > 0
                       for lm in result.landmarks)
    assert done >= 20  # nearly every hostile frame is still a frame
