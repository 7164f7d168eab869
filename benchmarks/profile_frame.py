"""Where a full-frame scan's CPU goes: cProfile of ``Pipeline.process`` on the benchmark's clean scenes.

Usage::

    python benchmarks/profile_frame.py [N_LANDMARKS] [--lines K] [--track]

Renders the same 640×480 scene family as ``bench.py`` (N drifting landmarks, 8 frames,
the shipped defaults), warms the pipeline on them once, then profiles 5 passes
and prints the K functions with the largest cumulative time (warm figures; the
profiler's overhead inflates small calls, so read the shares, not the milliseconds).
``--track`` profiles a tracking pipeline on 16 consecutive frames instead, and only
its tracked frames (those measured in windows, not the full scans between them).
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import sys

os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from bench_aruco import marker_images
from bench_frames import build_scenario

from rangebearing import Pipeline
from rangebearing.allocator import keep_freed_buffers
from rangebearing.config import Config


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("n", nargs="?", type=int, default=1, help="landmarks in view (default 1)")
    p.add_argument("--lines", type=int, default=28, help="functions to print (default 28)")
    p.add_argument("--track", action="store_true", help="profile the tracked frames of a tracking pipeline")
    args = p.parse_args(argv)
    keep_freed_buffers()  # as the daemon and bench.py run
    sc = build_scenario(Config(), 640, 480, args.n, 16 if args.track else 8, 640_000 + args.n, marker_images)
    pipe = Pipeline(sc.cfg.pipeline, track=args.track)
    for frame in sc.frames:
        pipe.process(frame)
    if args.track:
        return _tracked(pipe, sc.frames, args.lines)
    prof = cProfile.Profile()
    prof.enable()
    for _ in range(5):
        for frame in sc.frames:
            pipe.process(frame)
    prof.disable()
    pstats.Stats(prof).sort_stats("cumulative").print_stats(args.lines)
    return 0


def _tracked(pipe: Pipeline, frames: list, lines: int) -> int:
    """Profile each frame on its own and keep the tracked ones' profiles."""
    stats = None
    for _ in range(5):
        for frame in frames:
            prof = cProfile.Profile()
            prof.enable()
            result = pipe.process(frame)
            prof.disable()
            if result.tracked:
                stats = pstats.Stats(prof) if stats is None else stats.add(prof)
    if stats is None:
        print("no tracked frame", file=sys.stderr)
        return 1
    stats.sort_stats("cumulative").print_stats(lines)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
