"""Where a frame's CPU goes as the daemon pays it: each stage of ``Pipeline.process``, cold and paced.

Usage::

    python benchmarks/cold_stages.py [N_LANDMARKS] [--track] [--passes K] [--size WxH]

Renders the scene family of ``bench.py`` (N drifting landmarks, 16 frames), then
processes the frames one at a time after a sleep of 11–33 ms, with the paper's median
filter run on another frame in each gap (the other contenders' work in ``bench.py``'s
cold run), on one pinned core. Each stage is the core function ``Pipeline.process``
calls, wrapped to add its thread CPU time (a wrapper costs well under a microsecond:
unlike cProfile, small calls are not inflated). Stages nest as the code does: the
structure search ``detect.search`` runs inside ``pipeline.balanced_search``, the
band moments and rows inside ``pipeline.refine``, tracked frames' work inside
``pipeline.step``; ``refine.band_weights``/``tile_centroids`` inside every
``measure_bands``, ``measure.excess_luma``/``_rows`` (one per landmark) inside every
``measure_rows_all``, ``pipeline.white_clipped`` inside each reading. Printed: the
median frame, then each stage's mean per frame, full scans and tracked frames apart.
"""

from __future__ import annotations

import argparse
import collections
import importlib
import os
import random
import statistics
import sys
import time
from typing import Callable, Dict, List, Tuple

os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import cv2
from bench_aruco import marker_images
from bench_frames import build_scenario

from rangebearing import Pipeline
from rangebearing.allocator import keep_freed_buffers
from rangebearing.config import Config

#: (module under rangebearing.core, name in it): the calls of Pipeline.process timed as stages
STAGES = [
    ("pipeline", "downscale"), ("pipeline", "grey_world_gains"), ("pipeline", "balanced_search"),
    ("detect", "band_masks"), ("detect", "search"), ("detect", "search_apart"), ("balance", "white_body_gains"),
    ("pipeline", "refine"), ("detect", "measure_bands"), ("detect", "measure_rows_all"), ("detect", "combine"),
    ("pipeline", "verified"), ("pipeline", "drop_stacked"), ("pipeline", "chroma_blur_all"),
    ("pipeline", "step"), ("tracking", "measure_bands"), ("tracking", "measure_rows_all"), ("tracking", "combine"),
    ("pipeline", "side_view"), ("pipeline", "update"), ("pipeline", "reading"), ("pipeline", "reading_sigma"),
    ("pipeline", "white_clipped"), ("pipeline", "crossing"),
    ("refine", "band_weights"), ("refine", "tile_centroids"), ("measure", "excess_luma"), ("measure", "_rows"),
]


def wrap_stages(spent: Dict[str, int]) -> Callable[[], None]:
    """Wrap every stage so its thread CPU nanoseconds add up in ``spent``; returns the function that unwraps them."""
    undo = []
    for mod_name, name in STAGES:
        mod = importlib.import_module("rangebearing.core." + mod_name)
        fn = getattr(mod, name)

        def timed(*a, _fn=fn, _key=f"{mod_name}.{name}", **k):
            t0 = time.thread_time_ns()
            try:
                return _fn(*a, **k)
            finally:
                spent[_key] += time.thread_time_ns() - t0

        setattr(mod, name, timed)
        undo.append((mod, name, fn))
    return lambda: [setattr(m, n, f) for m, n, f in undo]


def run(n: int, track: bool, passes: int, size: Tuple[int, int], seed: int = 0
        ) -> Tuple[Dict[bool, List[int]], Dict[Tuple[str, bool], List[int]]]:
    """Frame CPU (ns) by tracked-or-not, and each stage's CPU per frame, over ``passes`` cold paced passes."""
    keep_freed_buffers()
    sc = build_scenario(Config(), size[0], size[1], n, 16, 640_000 + n, marker_images)
    pipe = Pipeline(sc.cfg.pipeline, track=track)
    for frame in sc.frames:  # imports, tables, caches: not what a frame costs
        pipe.process(frame)
    pipe = Pipeline(sc.cfg.pipeline, track=track)
    spent: Dict[str, int] = collections.Counter()
    unwrap = wrap_stages(spent)
    other = sc.frames[-1].copy()
    rng = random.Random(seed)
    frames: Dict[bool, List[int]] = {False: [], True: []}
    stages: Dict[Tuple[str, bool], List[int]] = collections.defaultdict(list)
    try:
        for _ in range(passes):
            for frame in sc.frames:
                time.sleep(rng.uniform(0.011, 0.033))
                cv2.medianBlur(other, 15)  # the caches cooled by other work, as in bench.py's cold run
                spent.clear()
                t0 = time.thread_time_ns()
                result = pipe.process(frame)
                frames[result.tracked].append(time.thread_time_ns() - t0)
                for key, ns in spent.items():
                    stages[(key, result.tracked)].append(ns)
    finally:
        unwrap()
    return frames, stages


def main(argv: List[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("n", nargs="?", type=int, default=1, help="landmarks in view (default 1)")
    p.add_argument("--track", action="store_true", help="a tracking pipeline: tracked frames and full scans apart")
    p.add_argument("--passes", type=int, default=3, help="passes over the 16 frames (default 3)")
    p.add_argument("--size", default="640x480", help="frame size WxH (default 640x480)")
    args = p.parse_args(argv)
    size = tuple(int(v) for v in args.size.lower().split("x"))
    cv2.setNumThreads(1)
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[-1]})
    frames, stages = run(args.n, args.track, args.passes, size)  # type: ignore[arg-type]
    for tracked in (False, True):
        ns = frames[tracked]
        if not ns:
            continue
        kind = "tracked frames" if tracked else "full scans"
        print(f"{args.size} N={args.n} {kind}: median {statistics.median(ns) / 1e6:.3f} ms CPU over {len(ns)} frames")
        rows = sorted(((k, sum(v)) for (k, t), v in stages.items() if t == tracked), key=lambda kv: -kv[1])
        for key, total in rows:
            print(f"  {key:28s} {total / len(ns) / 1e6:7.3f} ms a frame")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
