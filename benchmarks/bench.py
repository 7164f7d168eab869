"""Speed benchmark of rangebearing against the paper's pipeline and OpenCV ArUco, on one core.

Usage::

    python benchmarks/bench.py [--quick] [--repeats N] [--out benchmarks/RESULTS.md]

Prints markdown tables to stdout (progress goes to stderr); ``--out`` also
writes them to a file under a header describing the machine and the command.
See benchmarks/README.md for what each column means.
"""

from __future__ import annotations

import argparse
import os
import shlex
import sys
import time
from pathlib import Path
from typing import List, Optional

FULL = {"resolutions": [(320, 240), (640, 480), (1280, 720)], "counts": [0, 1, 5, 10], "frames": 16,
        "repeats": 7, "daemon_frames": 60, "daemon_s": 5.0}
QUICK = {"resolutions": [(320, 240)], "counts": [0, 1, 10], "frames": 4, "repeats": 1, "daemon_frames": 8,
         "daemon_s": 1.0}
DAEMON_FPS = 90.0
STAGE_COUNTS = (1, 10)


def _one_core() -> None:
    """Single-threaded numerics: BLAS pools must be told before numpy loads, OpenCV any time."""
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")


def parse_args(argv: Optional[List[str]]) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="bench.py",
        description="Time rangebearing (paper pipeline, default pipeline, tracking) and OpenCV ArUco on the same "
        "synthetic frames, on one core, and check that the daemon keeps up at 90 fps.",
    )
    p.add_argument("--quick", action="store_true", help="one small resolution, few frames, 1 repeat, 1 s daemon run")
    p.add_argument("--repeats", type=int, default=None, metavar="N",
                   help="timed passes over each scenario's frames (default 7, or 1 with --quick)")
    p.add_argument("--out", type=Path, default=None, metavar="FILE",
                   help="also write the tables, under a machine header, to FILE (e.g. benchmarks/RESULTS.md)")
    args = p.parse_args(argv)
    if args.repeats is not None and args.repeats < 1:
        p.error("--repeats must be at least 1")
    return args


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def main(argv: Optional[List[str]] = None) -> int:
    args = parse_args(argv)
    _one_core()
    import bench_aruco
    import cv2
    from bench_daemon import daemon_check
    from bench_frames import build_scenario
    from bench_report import Run, label, machine_header, render
    from bench_stages import stage_breakdown
    from bench_timing import measure_scenario

    from rangebearing import Config

    cv2.setNumThreads(1)
    plan = QUICK if args.quick else FULL
    repeats = args.repeats or plan["repeats"]
    base = Config()
    aruco = bench_aruco.make_detector() if bench_aruco.available() else None
    aruco_note = (f"ArUco: OpenCV {cv2.__version__}, {bench_aruco.DICT_NAME}, default DetectorParameters, "
                  "BGR→grey included." if aruco else
                  f"ArUco skipped: OpenCV {cv2.__version__} has no cv2.aruco (install opencv-contrib-python on 4.6).")
    stage_res = (640, 480) if (640, 480) in plan["resolutions"] else plan["resolutions"][0]
    run = Run(plan["resolutions"], plan["counts"], plan["frames"], repeats, {}, {}, label(*stage_res), {}, "", None,
              aruco_note)
    t_start = time.perf_counter()
    stage_frames = {}
    for w, h in plan["resolutions"]:
        for n in plan["counts"]:
            sc = build_scenario(base, w, h, n, plan["frames"], 1000 * w + n, bench_aruco.marker_images)
            _log(f"{sc.label}, {n} landmarks: timing …")
            run.figures[(sc.label, n)] = measure_scenario(sc, repeats, aruco)
            run.marker_scale[(sc.label, n)] = sc.marker_scale
            if (w, h) == stage_res and n in STAGE_COUNTS:
                stage_frames[n] = sc
    _log(f"stage breakdown at {run.stage_label} …")
    try:
        for n, sc in stage_frames.items():
            run.stages[n] = stage_breakdown(sc.cfg, sc.frames, repeats)
    except (ImportError, AttributeError, TypeError, ValueError) as exc:  # the pipeline's internals moved
        run.stage_error = f"{type(exc).__name__}: {exc} (update benchmarks/bench_stages.py)"
        _log(f"stage breakdown failed: {run.stage_error}")
    _log(f"daemon keep-up at {DAEMON_FPS:.0f} fps for {plan['daemon_s']:.0f} s …")
    w, h = stage_res
    clip = build_scenario(base, w, h, 1, plan["daemon_frames"], 7, bench_aruco.marker_images)
    run.daemon = daemon_check(clip.cfg, clip.frames, DAEMON_FPS, plan["daemon_s"])
    body = render(run)
    print(body)
    _log(f"done in {time.perf_counter() - t_start:.0f} s")
    if args.out is not None:
        given = sys.argv[1:] if argv is None else argv
        command = "python benchmarks/bench.py" + "".join(" " + shlex.quote(a) for a in given)
        args.out.write_text(machine_header(command) + "\n" + body, encoding="utf-8")
        _log(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
