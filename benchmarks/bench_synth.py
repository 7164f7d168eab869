"""Render time of every synth preset: one 640x480 frame, render and truth separately.

    python benchmarks/bench_synth.py [--frames N] [--size WxH]

Prints wall and CPU (process) seconds per frame; CPU time is the fairer figure on
a machine shared with other jobs.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rangebearing.core.types import CameraIntrinsics
from rangebearing.synth import PRESETS, render, scene_sequence, scene_truth


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=8)
    ap.add_argument("--size", default="640x480")
    args = ap.parse_args()
    w, h = (int(v) for v in args.size.split("x"))
    camera = CameraIntrinsics().scaled(w, h)
    print(f"| preset | render wall s | render CPU s | truth wall s | landmarks/frame |  ({w}x{h}, "
          f"{args.frames} frames each)")
    print("|---|---|---|---|---|")
    for preset in PRESETS:
        scenes = list(scene_sequence(np.random.default_rng(1), preset, args.frames, camera))
        rng = np.random.default_rng(2)
        wall, cpu = time.perf_counter(), time.process_time()
        for s in scenes:
            render(s, rng)
        wall, cpu = (time.perf_counter() - wall) / len(scenes), (time.process_time() - cpu) / len(scenes)
        t = time.perf_counter()
        rows = [scene_truth(s, "f") for s in scenes]
        truth = (time.perf_counter() - t) / len(scenes)
        n = sum(len(r) for r in rows) / len(scenes)
        print(f"| {preset} | {wall:.3f} | {cpu:.3f} | {truth:.3f} | {n:.1f} |")


if __name__ == "__main__":
    main()
