"""CPU time (and wall time) of the contenders on one scenario's frames, cold and warm, and what they found.

**Cold and paced** (the headline): frame by frame, every contender processes
the frame once, in a freshly shuffled order, each call after a sleep drawn
from ``gap_s`` (the daemon sleeps 11–33 ms between frames at 30–90 fps), so
each call finds the caches the way the daemon does: cooled by the sleep and
by the other contenders' work. **Warm**: one untimed pass, then each
contender runs over all frames back to back, passes interleaved; the old
figure, kept beside the cold one.

Each call is timed on the calling thread's CPU clock
(``time.thread_time_ns``: what the robot's other programs and battery pay;
OpenCV and the AprilTag library run on this thread, one core) and on the wall
clock (``time.perf_counter_ns``: latency). Peak memory is measured afterwards,
in a pass of its own under ``tracemalloc``.
"""

from __future__ import annotations

import dataclasses
import math
import random
import time
import tracemalloc
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np
from bench_frames import ScenarioFrames

from rangebearing import Config, FrameResult, Landmark, Pipeline
from rangebearing._compat import frozen
from rangebearing.evaluation.match import match_frame
from rangebearing.evaluation.truth import TruthRow
from rangebearing.synth.scene import LandmarkPose

Process = Callable[[np.ndarray], object]
PACED_GAP_S = (0.011, 0.033)


@dataclasses.dataclass
class Contender:
    """A named way of processing a frame; ``expected(i)`` is how many things it should report in frame i."""

    name: str
    process: Process
    expected: Callable[[int], int]
    what: str = "landmarks"  # or "markers"
    warm_cpu_ns: List[int] = dataclasses.field(default_factory=list)
    warm_wall_ns: List[int] = dataclasses.field(default_factory=list)
    warm_tracked: List[bool] = dataclasses.field(default_factory=list)
    cold_cpu_ns: List[int] = dataclasses.field(default_factory=list)
    cold_wall_ns: List[int] = dataclasses.field(default_factory=list)
    outputs: List[Tuple[int, object]] = dataclasses.field(default_factory=list)  # cold run: (frame index, output)


@frozen
class Figures:
    """What one contender did on one scenario (times in milliseconds per frame; CPU unless named wall)."""

    name: str
    cold_ms: float  # median CPU, cold and paced: the headline
    cold_p90_ms: float
    warm_ms: float  # median CPU, warm
    wall_cold_ms: float
    wall_cold_p99_ms: float
    wall_warm_ms: float
    found: str  # e.g. "5 of 5 landmarks ✓"
    found_ok: bool
    error: str  # worst range and bearing error against the truth, "" when not applicable
    peak_kib: float
    tracked_cold_ms: float = math.nan  # track only: frames searched in windows
    tracked_warm_ms: float = math.nan
    all_cold_mean_ms: float = math.nan  # track only: mean over every frame, full scans included
    tracked_share: float = math.nan


def rangebearing_contenders(sc: ScenarioFrames, markers: Dict[str, Process]) -> List[Contender]:
    """paper, full, full yuv (searching the YUV420 stream), track and the marker detectors (name → detect)."""
    cfg: Config = sc.cfg
    paper = dataclasses.replace(cfg, detection=dataclasses.replace(cfg.detection, method="paper"))

    def n_truth(i: int) -> int:
        return len(sc.truth[i % len(sc.truth)])

    out = [
        Contender("paper", Pipeline(paper.pipeline, track=False).process, n_truth),
        Contender("full", Pipeline(cfg.pipeline, track=False).process, n_truth),
    ]
    full_yuv = Pipeline(cfg.pipeline, track=False)
    by_frame = {id(f): y for f, y in zip(sc.frames, sc.yuv)}  # the camera hands both streams over together
    out.append(Contender("full yuv", lambda frame: full_yuv.process(frame, by_frame[id(frame)]), n_truth))
    if sc.sequence:  # tracking needs consecutive frames
        out.append(Contender("track", Pipeline(cfg.pipeline, track=True).process, n_truth))
    for name, detect in markers.items():
        n = sc.count(name.split()[0])
        out.append(Contender(name, detect, lambda i, n=n: n, "markers"))
    return out


def _tracked(out: object) -> bool:
    return isinstance(out, FrameResult) and out.tracked


def run_warm(contenders: Sequence[Contender], frames: Sequence[np.ndarray], repeats: int) -> None:
    """One untimed pass, then ``repeats`` passes of each contender over all frames, passes interleaved."""
    cpu, wall = time.thread_time_ns, time.perf_counter_ns
    for c in contenders:
        for frame in frames:
            c.process(frame)
    for _ in range(repeats):
        for c in contenders:
            fn = c.process
            for frame in frames:
                t0, w0 = cpu(), wall()
                out = fn(frame)
                w1, t1 = wall(), cpu()
                c.warm_cpu_ns.append(t1 - t0)
                c.warm_wall_ns.append(w1 - w0)
                c.warm_tracked.append(_tracked(out))


def run_cold(
    contenders: Sequence[Contender],
    frames: Sequence[np.ndarray],
    passes: int,
    gap_s: Tuple[float, float] = PACED_GAP_S,
    seed: int = 0,
    sleep: Callable[[float], object] = time.sleep,
) -> None:
    """Frame by frame, every contender once in shuffled order, each call after a sleep drawn from ``gap_s``."""
    cpu, wall = time.thread_time_ns, time.perf_counter_ns
    rng = random.Random(seed)
    order = list(contenders)
    for _ in range(passes):
        for i, frame in enumerate(frames):
            rng.shuffle(order)
            for c in order:
                sleep(rng.uniform(*gap_s))
                t0, w0 = cpu(), wall()
                out = c.process(frame)
                w1, t1 = wall(), cpu()
                c.cold_cpu_ns.append(t1 - t0)
                c.cold_wall_ns.append(w1 - w0)
                c.outputs.append((i, out))


def peak_kib(process: Process, frames: Sequence[np.ndarray]) -> float:
    """Largest ``tracemalloc`` peak (KiB) above the starting level while processing one frame."""
    tracemalloc.start()
    try:
        worst = 0
        for frame in frames:
            tracemalloc.reset_peak()
            before = tracemalloc.get_traced_memory()[0]
            process(frame)
            worst = max(worst, tracemalloc.get_traced_memory()[1] - before)
    finally:
        tracemalloc.stop()
    return worst / 1024.0


def count(out: object) -> int:
    """Landmarks in a FrameResult, or markers in a detector's id list/array (None: none)."""
    if isinstance(out, FrameResult):
        return len(out.landmarks)
    return 0 if out is None else len(out)  # type: ignore[arg-type]


def judged(out: FrameResult, sc: ScenarioFrames, i: int) -> Tuple[int, int, List[Tuple[LandmarkPose, Landmark]]]:
    """Frame ``i``'s readings against its truth: (findable landmarks, false readings, the findable ones found).

    Readings are matched (:func:`rangebearing.evaluation.match.match_frame`) to every landmark of the
    scene, so a reading of a partly hidden landmark the truth does not ask for is not false.
    """
    want = sc.truth[i % len(sc.truth)]
    seen = sc.seen[i % len(sc.seen)] if sc.seen else want
    rows = [TruthRow(str(i), lm.range_m, lm.bearing_rad, findable=any(lm is w for w in want)) for lm in seen]
    matches, false = match_frame(str(i), out.landmarks, rows)
    found = [(seen[j], m.found) for j, m in enumerate(matches) if m.truth.findable and m.found is not None]
    return len(want), len(false), found


def _errors(contender: Contender, sc: ScenarioFrames) -> str:
    """Worst relative range error and bearing error over every findable landmark found."""
    if contender.what != "landmarks" or sc.n_landmarks == 0:
        return ""
    worst_r = worst_b = -1.0
    for i, out in contender.outputs:
        if not isinstance(out, FrameResult):
            continue
        for t, g in judged(out, sc, i)[2]:
            worst_r = max(worst_r, abs(g.range_m - t.range_m) / t.range_m)
            worst_b = max(worst_b, abs(g.bearing_rad - t.bearing_rad))
    if worst_r < 0:
        return "–"
    return f"{100 * worst_r:.1f} % / {math.degrees(worst_b):.2f}°"


def _found(contender: Contender, sc: ScenarioFrames) -> Tuple[str, bool]:
    """What it found per frame against what it should have, ✓ when every frame was right.

    A landmark contender's frame is right when every findable landmark was found and no reading is
    false (:func:`judged`); a marker detector's when it counted the markers there are.
    """
    if contender.what == "landmarks" and all(isinstance(o, FrameResult) for _, o in contender.outputs):
        marks = [judged(o, sc, i) for i, o in contender.outputs]  # type: ignore[arg-type]
        got = [len(m[2]) for m in marks]
        false = sum(m[1] for m in marks)
        right = [len(m[2]) == m[0] and m[1] == 0 for m in marks]
    else:
        got = [count(o) for _, o in contender.outputs]
        false = 0
        right = [g == contender.expected(i) for g, (i, _) in zip(got, contender.outputs)]
    want = [contender.expected(i) for i, _ in contender.outputs]
    ok = all(right)
    if min(want) == max(want):
        text = f"{min(got)}–{max(got)}" if min(got) != max(got) else f"{got[0]}"
        text = f"{text} of {want[0]} {contender.what}"
    else:
        text = f"{sum(right)}/{len(got)} frames right ({min(want)}–{max(want)} {contender.what})"
    if false:
        text += f", {false} false"
    note = " (≤ 1 by design)" if contender.name == "paper" and max(want) > 1 else ""
    return f"{text} {'✓' if ok else '✗'}{note}", ok


def _median_ms(ns: Sequence[int], mask: Optional[np.ndarray] = None) -> float:
    t = np.asarray(ns, dtype=np.float64) / 1e6
    if mask is not None:
        t = t[mask]
    return float(np.median(t)) if t.size else math.nan


def summarise(c: Contender, sc: ScenarioFrames, peak: float) -> Figures:
    """Cold and warm medians, latency percentiles, what was found, and the track-only figures."""
    cold = np.asarray(c.cold_cpu_ns, dtype=np.float64) / 1e6
    wall = np.asarray(c.cold_wall_ns, dtype=np.float64) / 1e6
    found, ok = _found(c, sc)
    extra: Dict[str, float] = {}
    if c.name == "track":
        tracked = np.array([_tracked(o) for _, o in c.outputs], bool)
        extra = {
            "tracked_cold_ms": _median_ms(c.cold_cpu_ns, tracked),
            "tracked_warm_ms": _median_ms(c.warm_cpu_ns, np.array(c.warm_tracked, bool)),
            "all_cold_mean_ms": float(cold.mean()),
            "tracked_share": float(tracked.mean()),
        }
    return Figures(
        name=c.name,
        cold_ms=float(np.median(cold)),
        cold_p90_ms=float(np.percentile(cold, 90)),
        warm_ms=_median_ms(c.warm_cpu_ns),
        wall_cold_ms=float(np.median(wall)),
        wall_cold_p99_ms=float(np.percentile(wall, 99)),
        wall_warm_ms=_median_ms(c.warm_wall_ns),
        found=found,
        found_ok=ok,
        error=_errors(c, sc),
        peak_kib=peak,
        **extra,
    )


def measure_scenario(
    sc: ScenarioFrames,
    repeats: int,
    passes: int,
    markers: Dict[str, Process],
    gap_s: Tuple[float, float] = PACED_GAP_S,
    seed: int = 0,
) -> Dict[str, Figures]:
    """Time every contender warm, then cold and paced, then measure its memory; figures by name."""
    contenders = rangebearing_contenders(sc, markers)
    run_warm(contenders, sc.frames, repeats)
    for c in contenders:
        if c.name == "track":  # start the cold run on a fresh track, like a daemon that just woke up
            c.process = Pipeline(sc.cfg.pipeline, track=True).process
    run_cold(contenders, sc.frames, passes, gap_s, seed)
    return {c.name: summarise(c, sc, peak_kib(c.process, sc.frames)) for c in contenders}
