"""Per-frame cost of track identity (association + Kalman filters), in microseconds.

Usage: ``python benchmarks/bench_identity.py [--frames N]``. Prints one line per
landmark count: the mean CPU time of :func:`rangebearing.core.identity.update`
over a sequence of moving neighbours (steady state: every track matched), and
over the same sequence while pairs of neighbours cross (overlapping gates, so
the Hungarian solver runs). No pass/fail: figures only.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from typing import List

import numpy as np

from rangebearing.core.identity import IdentityParams, empty_state, update
from rangebearing.core.identity_landmarks import identify
from rangebearing.core.types import Landmark


def readings(n: int, frames: int, crossing: bool, seed: int = 0) -> List[np.ndarray]:
    """``frames`` arrays of ``(n, 2)`` noisy (range, bearing) readings of ``n`` moving neighbours."""
    rng = np.random.default_rng(seed)
    r0 = rng.uniform(0.3, 1.8, n)
    b0 = np.linspace(-0.4, 0.4, n)
    rate = rng.uniform(-0.3, 0.3, n)
    if crossing:  # neighbours in pairs drifting through each other, at similar ranges
        rate = np.where(np.arange(n) % 2 == 0, 0.4, -0.4)
        r0 = np.repeat(rng.uniform(0.4, 1.5, (n + 1) // 2), 2)[:n] + rng.uniform(0, 0.02, n)
        b0 = np.repeat(np.linspace(-0.4, 0.4, (n + 1) // 2), 2)[:n] - 0.12 * np.sign(rate)
    out = []
    for i in range(frames):
        t = i / 30.0
        z = np.stack([r0 + 0.05 * np.sin(t), b0 + rate * t], axis=1)
        out.append(z + rng.normal(0.0, [0.003, 0.002], z.shape))
    return out


def bench(n: int, frames: int, crossing: bool) -> float:
    """Mean CPU µs per frame of ``update`` for ``n`` landmarks (CPU time: a busy machine does not inflate it)."""
    seq = readings(n, frames, crossing)
    params = IdentityParams()
    sig_r, sig_b = np.full(n, 0.003), np.full(n, 0.002)
    state = empty_state()
    for i, z in enumerate(seq[:5]):  # warm up
        state, _ = update(state, z[:, 0], z[:, 1], sig_r, sig_b, i / 30.0, params)
    t0 = time.process_time_ns()
    for i, z in enumerate(seq[5:], 5):
        state, _ = update(state, z[:, 0], z[:, 1], sig_r, sig_b, i / 30.0, params)
    return (time.process_time_ns() - t0) / (len(seq) - 5) / 1e3


def bench_landmarks(n: int, frames: int) -> float:
    """Mean CPU µs per frame of ``identify`` (what the pipeline pays: arrays out of and ids back into Landmarks)."""
    seq = readings(n, frames, False)
    base = Landmark(0.5, 0.0, 0.5, 0.0, 60.0, (300.0, 200.0), (300.0, 260.0), 20.0, (290, 190, 20, 80), True,
                    range_sigma_m=0.003, bearing_sigma_rad=0.002)
    state = empty_state()
    frames_lms = [[Landmark(r, b, *dataclasses.astuple(base)[2:]) for r, b in z] for z in seq]
    for i, lms in enumerate(frames_lms[:5]):
        state, _ = identify(state, lms, i / 30.0)
    t0 = time.process_time_ns()
    for i, lms in enumerate(frames_lms[5:], 5):
        state, _ = identify(state, lms, i / 30.0)
    return (time.process_time_ns() - t0) / (len(seq) - 5) / 1e3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=300)
    args = ap.parse_args()
    print("landmarks  steady µs/frame  crossing µs/frame  with Landmarks µs/frame")
    for n in (1, 5, 10, 16):
        print(f"{n:9d}  {bench(n, args.frames, False):15.1f}  {bench(n, args.frames, True):17.1f}"
              f"  {bench_landmarks(n, args.frames):23.1f}")


if __name__ == "__main__":
    main()
