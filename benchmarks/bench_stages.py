"""Where the default pipeline's time goes: its full-frame path, stage by stage, on BGR and on the YUV search.

:func:`stage_breakdown` calls the core functions in the order
``Pipeline.process`` does on a full scan (see ``core/pipeline.py``,
``core/detect.py`` and ``core/yuv.py``). When the pipeline's internals are
renamed or reordered, this one function is what to update. Times are CPU time
of the thread (warm: frames back to back).
"""

from __future__ import annotations

import collections
import statistics
import time
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from rangebearing import Config, Pipeline


class Laps:
    """CPU nanoseconds between consecutive :meth:`lap` calls, collected per stage name."""

    def __init__(self) -> None:
        self.ns: Dict[str, List[int]] = collections.defaultdict(list)
        self._last = time.thread_time_ns()

    def start(self) -> None:
        self._last = time.thread_time_ns()

    def lap(self, name: str) -> None:
        now = time.thread_time_ns()
        self.ns[name].append(now - self._last)
        self._last = now


def stage_breakdown(
    cfg: Config, frames: Sequence[np.ndarray], repeats: int, yuvs: Optional[Sequence[object]] = None
) -> Tuple[List[Tuple[str, float]], int]:
    """Median CPU milliseconds per stage of a full-frame scan, plus the whole ``Pipeline.process``.

    Returns ``([(stage, median_ms), …], landmarks_found)``, the count from the
    last frame, so a breakdown that finds nothing is visible. With ``yuvs``
    (the frames' YUV420 streams) the search stages of the YUV path follow,
    prefixed ``yuv:``.
    """
    from rangebearing.core.color import apply_gains, class_masks, grey_world_gains, to_hsv
    from rangebearing.core.denoise import majority_filter
    from rangebearing.core.detect import downscale, refine
    from rangebearing.core.model import in_envelope, reading
    from rangebearing.core.refine import Pyramid
    from rangebearing.core.structure import search
    from rangebearing.core.yuv import WindowHsv, chroma_masks, half_luma, yuv_grey_world_gains

    det, geom = cfg.detection, cfg.landmark
    s = det.downscale
    pipe = Pipeline(cfg.pipeline, track=False)
    h, w = frames[0].shape[:2]
    cam, ksize = pipe._camera(w, h)
    min_area = max(2, int(det.min_band_px * det.min_band_px / (s * s)))
    laps = Laps()
    found = 0
    for rep in range(repeats + 1):  # the first pass warms up
        if rep == 1:
            laps = Laps()
        for k, frame in enumerate(frames):
            laps.start()
            small = downscale(frame, s)
            laps.lap(f"downscale 1/{s} (2×2 average)")
            gains = grey_world_gains(small)
            laps.lap("grey_world_gains (robust, 40×30 thumbnail)")
            hsv = to_hsv(apply_gains(small, gains))
            laps.lap("apply_gains + to_hsv")
            red, blue = class_masks(hsv, det.red_hue, det.blue_hue, det.s_min, det.v_min)
            laps.lap("class_masks")
            red, blue = majority_filter(red, ksize), majority_filter(blue, ksize)
            laps.lap(f"majority_filter ×2 (k={ksize})")
            cands = search(red, blue, hsv, s, geom, det.max_landmarks, min_area).candidates
            laps.lap("candidates (regions, pairs, column structure)")
            found_c = refine(frame, cands, det, gains, geom, cam.fy_px, Pyramid(frame, small if s == 2 else None))
            laps.lap("refine (sub-pixel bands, rows from edges)")
            for c in found_c:
                rng, bearing, *_ = reading(c.red_xy_px, c.blue_xy_px, cam, cfg.model, geom)
                in_envelope(rng, bearing, cfg.model)
            laps.lap("model: reading + in_envelope")
            found = len(found_c)
            if yuvs is not None and s == 2:
                yuv = yuvs[k]
                laps.start()
                y_half = half_luma(yuv.y)
                laps.lap("yuv: half_luma (Y 2×2 mean)")
                gains = yuv_grey_world_gains(yuv, y_half=y_half)
                laps.lap("yuv: grey-world gains (thumbnail)")
                red, blue = chroma_masks(yuv, det, gains, y_half)
                laps.lap("yuv: chroma_masks (table on U, V; Y bounds)")
                red, blue = majority_filter(red, ksize), majority_filter(blue, ksize)
                laps.lap(f"yuv: majority_filter ×2 (k={ksize})")
                search(red, blue, WindowHsv(y_half, yuv, gains), 2, geom, det.max_landmarks, min_area)
                laps.lap("yuv: candidates (HSV of the windows only)")
        for k, frame in enumerate(frames):  # passes of their own, so they do not find the frame warm in cache
            laps.start()
            pipe.process(frame)
            laps.lap("Pipeline.process (whole, BGR)")
            if yuvs is not None:
                laps.start()
                pipe.process(frame, yuvs[k])
                laps.lap("Pipeline.process (whole, YUV search)")
    return [(name, statistics.median(ns) / 1e6) for name, ns in laps.ns.items()], found
