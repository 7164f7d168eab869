"""Where the default pipeline's time goes: its full-frame path, stage by stage.

:func:`stage_breakdown` calls the core functions in the order
``Pipeline.process`` does on a full scan (see ``core/pipeline.py`` and
``core/detect.py``). When the pipeline's internals are renamed or reordered,
this one function is what to update.
"""

from __future__ import annotations

import collections
import statistics
import time
from typing import Dict, List, Sequence, Tuple

import numpy as np

from rangebearing import Config, Pipeline


class Laps:
    """Nanoseconds between consecutive :meth:`lap` calls, collected per stage name."""

    def __init__(self) -> None:
        self.ns: Dict[str, List[int]] = collections.defaultdict(list)
        self._last = time.perf_counter_ns()

    def start(self) -> None:
        self._last = time.perf_counter_ns()

    def lap(self, name: str) -> None:
        now = time.perf_counter_ns()
        self.ns[name].append(now - self._last)
        self._last = now


def stage_breakdown(cfg: Config, frames: Sequence[np.ndarray], repeats: int) -> Tuple[List[Tuple[str, float]], int]:
    """Median milliseconds per stage of a full-frame scan, plus the whole ``Pipeline.process``.

    Returns ``([(stage, median_ms), …, ("Pipeline.process (whole)", ms)], landmarks_found)``,
    the count from the last frame, so a breakdown that finds nothing is visible.
    """
    from rangebearing.core.blobs import find_boxes
    from rangebearing.core.color import apply_gains, class_masks, grey_world_gains, to_hsv
    from rangebearing.core.denoise import band_preserving_ksize, majority_filter
    from rangebearing.core.detect import downscale, refine
    from rangebearing.core.model import in_envelope, reading
    from rangebearing.core.pairing import PairingLimits, pair_bands
    from rangebearing.core.refine import Pyramid

    det, geom, cam = cfg.detection, cfg.landmark, cfg.camera
    s = det.downscale
    band_px = cam.fy_px * geom.band_height_m / cfg.model.envelope_range_m[1] / s
    ksize = band_preserving_ksize(det.median_ksize, band_px)
    limits, min_area = PairingLimits(), det.min_band_px * det.min_band_px
    pipe = Pipeline(cfg.pipeline, track=False)
    laps = Laps()
    found = 0
    for rep in range(repeats + 1):  # the first pass warms up
        if rep == 1:
            laps = Laps()
        for frame in frames:
            laps.start()
            small = downscale(frame, s)
            laps.lap(f"downscale 1/{s} (2×2 average)")
            gains = grey_world_gains(small)
            laps.lap("grey_world_gains (downscaled frame)")
            balanced = apply_gains(small, gains)
            laps.lap("region_masks: apply_gains")
            hsv = to_hsv(balanced)
            laps.lap("region_masks: to_hsv")
            red, blue = class_masks(hsv, det.red_hue, det.blue_hue, det.s_min, det.v_min)
            laps.lap("region_masks: class_masks")
            red, blue = majority_filter(red, ksize), majority_filter(blue, ksize)
            laps.lap(f"region_masks: majority_filter ×2 (k={ksize})")
            reds = find_boxes(red, s, min_area)
            blues = find_boxes(blue, s, min_area)
            laps.lap("find_boxes ×2")
            idx = np.array(pair_bands(reds, blues, geom, limits, det.max_landmarks), np.int64).reshape(-1, 2)
            laps.lap("pair_bands")
            centroids = refine(
                frame, reds[idx[:, 0]], blues[idx[:, 1]], det, gains, Pyramid(frame, small if s == 2 else None)
            )
            laps.lap("refine (sub-pixel moments)")
            for c in centroids:
                rng, bearing, *_ = reading(c.red_xy_px, c.blue_xy_px, cam, cfg.model, geom)
                in_envelope(rng, bearing, cfg.model)
            laps.lap("model: reading + in_envelope")
            found = len(centroids)
        for frame in frames:  # a pass of its own, so it does not find the frame warm in cache
            laps.start()
            pipe.process(frame)
            laps.lap("Pipeline.process (whole)")
    return [(name, statistics.median(ns) / 1e6) for name, ns in laps.ns.items()], found
