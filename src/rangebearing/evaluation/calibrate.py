"""Calibration from frames with known range and bearing: detect, match, fit.

The library side of ``rangebearing calibrate``; the least squares live in
:mod:`rangebearing.core.fit`.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Iterable, List, Optional, Sequence, Tuple

import numpy as np

from ..config import Config
from ..core.fit import Fit, Sample, fit_model
from ..core.pipeline import Pipeline
from .match import match_frame
from .truth import TruthRow

# Before calibration the model may be far off; match detections to truth loosely.
CALIBRATION_GAP_RAD = math.radians(10.0)

Frames = Iterable[Tuple[str, Optional[np.ndarray], Sequence[TruthRow]]]


def collect_samples(frames: Frames, cfg: Config) -> List[Sample]:
    """Detect landmarks in ``(name, image, truth rows)`` frames and pair them with their truth.

    Frames without truth rows or without an image are skipped.
    """
    pipe = Pipeline(cfg.pipeline, track=False)
    samples = []
    for name, image, rows in frames:
        if image is None or not rows:
            continue
        h, w = image.shape[:2]
        cam = cfg.camera.for_frame(w, h)
        matches, _ = match_frame(name, pipe.process(image).landmarks, rows, CALIBRATION_GAP_RAD)
        for m in matches:
            if m.found is None:
                continue
            lm = m.found
            px_left = cam.cx_px - 0.5 * (lm.red_xy_px[0] + lm.blue_xy_px[0])
            l_norm = lm.l_px / cam.fy_px
            samples.append(Sample(name, lm.l_px, l_norm, lm.bearing_rad, px_left, m.truth.range_m, m.truth.bearing_rad))
    return samples


def calibrate(frames: Frames, cfg: Config) -> Tuple[Config, Fit]:
    """Fit ``cfg.model`` to the frames; returns the calibrated config and the fit.

    Raises
    ------
    CalibrationError
        Too few detections, a single distance, or an unphysical fit.
    """
    fit = fit_model(collect_samples(frames, cfg), cfg.model)
    return dataclasses.replace(cfg, model=fit.model), fit
