"""Calibration from frames with known range and bearing: detect, match, fit.

The library side of ``rangebearing calibrate``; the least squares live in
:mod:`rangebearing.core.fit`.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Callable, Iterable, Iterator, List, Optional, Sequence, Tuple

import numpy as np

from ..config import Config
from ..core.fit import Fit, Sample, fit_model
from ..core.focal_check import FocalCheck, check_focal
from ..core.model import normalised
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
            y_norm = float(normalised(np.array([lm.red_xy_px, lm.blue_xy_px]), cam)[:, 1].mean())
            samples.append(Sample(name, lm.l_px, l_norm, lm.bearing_rad, px_left, m.truth.range_m, m.truth.bearing_rad,
                                  y_norm))
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


Frame = Tuple[str, Optional[np.ndarray], Sequence[TruthRow]]


def _sized(frames: Frames, seen: List[Tuple[int, int]]) -> Iterator[Frame]:
    """The frames unchanged; ``seen`` ends up holding the size of the last image."""
    for name, image, rows in frames:
        if image is not None:
            seen[:] = [(image.shape[1], image.shape[0])]
        yield name, image, rows


def calibrate_checked(
    make_frames: Callable[[], Frames], cfg: Config, fit_focal: bool = False
) -> Tuple[Config, Fit, FocalCheck, bool]:
    """:func:`calibrate` plus the focal-length check; with ``fit_focal``, a wrong focal length is fixed.

    ``make_frames`` returns a fresh iterator of the frames each time it is
    called: a second pass runs when the bearings say the focal length is wrong
    and ``fit_focal`` is set, with ``fx``, ``fy`` (same factor) and ``cx``
    replaced by the fitted ones. Returns the config, the fit, the check (of the
    intrinsics as configured) and whether the camera was refitted.
    """
    size: List[Tuple[int, int]] = []
    samples = collect_samples(_sized(make_frames(), size), cfg)
    fit = fit_model(samples, cfg.model)
    cam = cfg.camera
    w, h = size[0] if size else (cam.width_px, cam.height_px)
    frame_cam = cam if (cam.width_px, cam.height_px) == (w, h) else cam.scaled(w, h)
    check = check_focal(samples, frame_cam.fx_px, frame_cam.cx_px)
    out = dataclasses.replace(cfg, model=fit.model)
    if not (fit_focal and check.fitted and check.suspect):
        return out, fit, check, False
    k = cam.width_px / w  # frame pixels → the config camera's pixels
    fx = check.fx_px * k
    new_cam = dataclasses.replace(
        cam, fx_px=fx, fy_px=cam.fy_px * fx / cam.fx_px, cx_px=(check.cx_px + 0.5) * k - 0.5
    )
    refit_cfg = dataclasses.replace(cfg, camera=new_cam)
    fit = fit_model(collect_samples(make_frames(), refit_cfg), cfg.model)
    return dataclasses.replace(refit_cfg, model=fit.model), fit, check, True
