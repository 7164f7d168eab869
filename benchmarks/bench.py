"""Speed benchmark of rangebearing against the paper's pipeline, OpenCV ArUco and AprilTag 3, on one core.

Usage::

    python benchmarks/bench.py [--quick] [--repeats N] [--passes N] [--out benchmarks/RESULTS.md]

Prints markdown tables to stdout (progress goes to stderr); ``--out`` also
writes them to a file under a header describing the machine and the command.
The headline is CPU time per frame, cold and paced; see benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import shlex
import sys
import time
from pathlib import Path
from typing import Dict, List, Optional

FULL = {"resolutions": [(320, 240), (640, 480), (1280, 720)], "counts": [0, 1, 5, 10], "frames": 16,
        "repeats": 5, "passes": 3, "gap_s": (0.011, 0.033), "hard": ("clutter", "crowd", "touching", "occlusion",
                                                                       "sample", "crowd-moving"),
        "hard_frames": 16, "daemon_frames": 60, "daemon": ((30.0, 10.0), (90.0, 5.0))}
QUICK = {"resolutions": [(320, 240)], "counts": [0, 1, 10], "frames": 4, "repeats": 1, "passes": 1,
         "gap_s": (0.002, 0.005), "hard": ("clutter", "sample"), "hard_frames": 4, "daemon_frames": 8,
         "daemon": ((30.0, 1.0), (90.0, 1.0))}
STAGE_COUNTS = (1, 10)


def _one_core() -> str:
    """Single-threaded numerics on one CPU: BLAS pools must be told before numpy loads, OpenCV any time."""
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    if not hasattr(os, "sched_setaffinity"):
        return "not pinned (no sched_setaffinity)"
    cpu = max(os.sched_getaffinity(0))
    os.sched_setaffinity(0, {cpu})
    return f"pinned to CPU {cpu}"


def parse_args(argv: Optional[List[str]]) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="bench.py",
        description="Time rangebearing (paper pipeline, default pipeline, tracking), OpenCV ArUco and AprilTag 3 "
        "on the same synthetic frames, cold and paced, on one core; run the daemon paced at 30 and 90 fps.",
    )
    p.add_argument("--quick", action="store_true", help="one small resolution, few frames, 1 pass, 1 s daemon runs")
    p.add_argument("--repeats", type=int, default=None, metavar="N",
                   help="warm passes over each scenario's frames (default 5, or 1 with --quick)")
    p.add_argument("--passes", type=int, default=None, metavar="N",
                   help="cold, paced passes over each scenario's frames (default 3, or 1 with --quick)")
    p.add_argument("--out", type=Path, default=None, metavar="FILE",
                   help="also write the tables, under a machine header, to FILE (e.g. benchmarks/RESULTS.md)")
    args = p.parse_args(argv)
    for name in ("repeats", "passes"):
        if getattr(args, name) is not None and getattr(args, name) < 1:
            p.error(f"--{name} must be at least 1")
    return args


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def marker_contenders() -> Dict[str, object]:
    """ArUco and AprilTag detectors that this machine has, by contender name; and notes on what is missing."""
    import bench_apriltag
    import bench_aruco

    out: Dict[str, object] = {}
    if bench_aruco.available():
        out["aruco"] = bench_aruco.make_detector()
    if bench_apriltag.available():
        for dec in bench_apriltag.DECIMATES:
            out[f"apriltag d{dec:.0f}"] = bench_apriltag.make_detector(dec)
    return out


def main(argv: Optional[List[str]] = None) -> int:
    args = parse_args(argv)
    pinned = _one_core()
    import bench_apriltag
    import bench_aruco
    import cv2
    from bench_daemon import daemon_run
    from bench_frames import build_scenario, preset_scenario
    from bench_report import Run, clean, label, machine_header, render
    from bench_stages import stage_breakdown
    from bench_timing import measure_scenario

    from rangebearing import Config
    from rangebearing.synth import PRESETS

    cv2.setNumThreads(1)
    from rangebearing.allocator import keep_freed_buffers

    keep_freed_buffers()  # as the daemon does (rangebearing run): no page faults for a frame's buffers
    plan = QUICK if args.quick else FULL
    repeats = args.repeats or plan["repeats"]
    passes = args.passes or plan["passes"]
    base = Config()  # crowd scenes hold more landmarks than one datagram carries (the default cap): find them all
    base = dataclasses.replace(base, detection=dataclasses.replace(base.detection, max_landmarks=16))
    markers = marker_contenders()
    notes = [f"CPU {pinned}."]
    notes.append(f"ArUco: OpenCV {cv2.__version__}, {bench_aruco.DICT_NAME}, default DetectorParameters, BGR→grey "
                 "included." if "aruco" in markers else f"ArUco skipped: OpenCV {cv2.__version__} has no cv2.aruco.")
    notes.append(f"AprilTag 3: pupil-apriltags {bench_apriltag.version()}, {bench_apriltag.FAMILY}, quad_decimate 2 "
                 "(d2) and 1 (d1), nthreads 1, BGR→grey included." if bench_apriltag.available() else
                 "AprilTag skipped: pupil-apriltags is not installed (pip install -e '.[bench]').")
    hard = [p for p in plan["hard"] if p in PRESETS]
    missing = [p for p in plan["hard"] if p not in PRESETS]
    if missing:
        notes.append(f"Presets not in this synth (skipped): {', '.join(missing)}.")
    stage_res = (640, 480) if (640, 480) in plan["resolutions"] else plan["resolutions"][0]
    run = Run(plan["resolutions"], plan["counts"], plan["frames"], repeats, passes, plan["gap_s"], {}, {}, {},
              label(*stage_res), {}, "", [], notes)
    images = {"aruco": bench_aruco.marker_images, "apriltag": bench_apriltag.tag_images}
    t_start = time.perf_counter()
    stage_frames = {}

    def measure(key, sc) -> None:
        _log(f"{key[0]} {key[1]}: timing …")
        run.figures[key] = measure_scenario(sc, repeats, passes, markers, plan["gap_s"], seed=hash(key) & 0xFFFF)
        run.marker_scale[key] = sc.marker_scale
        run.truth_counts[key] = sum(len(t) for t in sc.truth) / max(1, len(sc.truth))

    for w, h in plan["resolutions"]:
        for n in plan["counts"]:
            sc = build_scenario(base, w, h, n, plan["frames"], 1000 * w + n, images)
            measure((sc.label, clean(n)), sc)
            if (w, h) == stage_res and n in STAGE_COUNTS:
                stage_frames[n] = sc
    for i, preset in enumerate(hard):
        sc = preset_scenario(base, *stage_res, preset, plan["hard_frames"], 500 + i)
        measure((sc.label, preset), sc)
    _log(f"stage breakdown at {run.stage_label} …")
    try:
        for n, sc in stage_frames.items():
            run.stages[n] = stage_breakdown(sc.cfg, sc.frames, repeats, sc.yuv)
    except (ImportError, AttributeError, TypeError, ValueError) as exc:  # the pipeline's internals moved
        run.stage_error = f"{type(exc).__name__}: {exc} (update benchmarks/bench_stages.py)"
        _log(f"stage breakdown failed: {run.stage_error}")
    clip = build_scenario(Config(), *stage_res, 1, plan["daemon_frames"], 7, images)  # the shipped defaults
    for fps, seconds in plan["daemon"]:
        _log(f"daemon at {fps:.0f} fps for {seconds:.0f} s …")
        run.daemon.append(daemon_run(clip.cfg, clip.frames, fps, seconds))
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
