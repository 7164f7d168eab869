"""benchmarks/cold_stages.py runs, attributes CPU to the pipeline's stages and leaves the core unwrapped.

No timing is asserted (speed is judged in the benchmark's printed figures).
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

BENCH_DIR = Path(__file__).resolve().parents[1] / "benchmarks"


def test_cold_stages_times_the_stages_of_full_scans_and_tracked_frames_then_unwraps_them():
    sys.path.insert(0, str(BENCH_DIR))
    try:
        cold = importlib.import_module("cold_stages")
        from rangebearing.core import detect, pipeline

        before = (pipeline.refine, pipeline.balanced_search, detect.search)
        frames, stages = cold.run(1, True, 1, (320, 240))
        assert (pipeline.refine, pipeline.balanced_search, detect.search) == before  # no wrapper left behind
        assert len(frames[False]) + len(frames[True]) == 16 and frames[False] and frames[True]
        full = {k for k, tracked in stages if not tracked}
        tracked = {k for k, t in stages if t}
        assert {"pipeline.balanced_search", "detect.search", "pipeline.refine", "detect.measure_rows_all"} <= full
        assert "pipeline.step" in tracked and "pipeline.balanced_search" not in tracked
        # a stage inside another costs no more than the one holding it, frame by frame
        nested = (("detect.search", "pipeline.balanced_search"), ("detect.measure_rows_all", "pipeline.refine"))
        for inner, outer in nested:
            assert all(i <= o for i, o in zip(stages[(inner, False)], stages[(outer, False)]))
    finally:
        sys.path.remove(str(BENCH_DIR))
