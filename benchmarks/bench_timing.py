"""Timing and memory of the contenders on one scenario's frames, and a check of what they found.

Every contender runs a warm-up pass over the frames (not timed), then the
passes are interleaved (pass 1 of each contender, then pass 2 of each …), so a
burst of background load hits all contenders alike. Only the call itself is
timed. Peak memory is measured afterwards, in a separate pass under
``tracemalloc`` (which slows allocation, so never while timing).
"""

from __future__ import annotations

import dataclasses
import math
import statistics
import time
import tracemalloc
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np
from bench_frames import ScenarioFrames

from rangebearing import Config, FrameResult, Pipeline
from rangebearing._compat import frozen

Process = Callable[[np.ndarray], object]


@dataclasses.dataclass
class Contender:
    """A named way of processing a frame; ``expected`` is how many things it should report per frame."""

    name: str
    process: Process
    expected: int
    times_ns: List[int] = dataclasses.field(default_factory=list)
    outputs: List[object] = dataclasses.field(default_factory=list)
    run_medians_ns: List[float] = dataclasses.field(default_factory=list)


@frozen
class Figures:
    """What one contender did on one scenario (times in milliseconds)."""

    name: str
    median_ms: float
    p90_ms: float
    spread_ms: Tuple[float, float]  # lowest and highest per-pass median
    found: str  # e.g. "16/16 frames: 5 ✓"
    found_ok: bool
    error: str  # worst range and bearing error against the truth, "" when not applicable
    peak_kib: float
    tracked_median_ms: float = math.nan  # track only: frames searched in windows
    all_mean_ms: float = math.nan  # track only: mean over every frame, full scans included
    tracked_share: float = math.nan


def rangebearing_contenders(sc: ScenarioFrames, aruco: Optional[Process]) -> List[Contender]:
    """paper, full, track and (if available) aruco, for one scenario."""
    cfg: Config = sc.cfg
    paper = dataclasses.replace(cfg, detection=dataclasses.replace(cfg.detection, method="paper"))
    out = [
        Contender("paper", Pipeline(paper.pipeline, track=False).process, sc.n_landmarks),
        Contender("full", Pipeline(cfg.pipeline, track=False).process, sc.n_landmarks),
        Contender("track", Pipeline(cfg.pipeline, track=True).process, sc.n_landmarks),
    ]
    if aruco is not None:
        out.append(Contender("aruco", aruco, len(sc.markers)))
    return out


def run_timed(contenders: Sequence[Contender], frames: Sequence[np.ndarray], repeats: int) -> None:
    """One warm-up pass, then ``repeats`` interleaved timed passes; fills times, outputs, run medians."""
    clock = time.perf_counter_ns
    for c in contenders:
        for frame in frames:
            c.process(frame)
    for _ in range(repeats):
        for c in contenders:
            fn, pass_ns = c.process, []
            for frame in frames:
                t0 = clock()
                out = fn(frame)
                t1 = clock()
                pass_ns.append(t1 - t0)
                c.outputs.append(out)
            c.times_ns.extend(pass_ns)
            c.run_medians_ns.append(statistics.median(pass_ns))


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


def _count(out: object) -> int:
    if isinstance(out, FrameResult):
        return len(out.landmarks)
    return 0 if out is None else len(out)  # type: ignore[arg-type]


def _errors(contender: Contender, sc: ScenarioFrames) -> str:
    """Worst relative range error and bearing error over the frames where the count was right."""
    if contender.name == "aruco" or sc.n_landmarks == 0:
        return ""
    worst_r = worst_b = -1.0
    k = len(sc.frames)
    for i, out in enumerate(contender.outputs):
        if not isinstance(out, FrameResult):
            continue
        truth = sorted(sc.truth[i % k], key=lambda lm: lm.bearing_rad)
        got = sorted(out.landmarks, key=lambda lm: lm.bearing_rad)
        if len(got) != len(truth):
            continue
        for g, t in zip(got, truth):
            worst_r = max(worst_r, abs(g.range_m - t.range_m) / t.range_m)
            worst_b = max(worst_b, abs(g.bearing_rad - t.bearing_rad))
    if worst_r < 0:
        return "–"
    return f"{100 * worst_r:.1f} % / {math.degrees(worst_b):.2f}°"


def _found(contender: Contender, sc: ScenarioFrames) -> Tuple[str, bool]:
    counts = [_count(o) for o in contender.outputs]
    good = sum(c == contender.expected for c in counts)
    ok = good == len(counts)
    what = "markers" if contender.name == "aruco" else "landmarks"
    text = f"{min(counts)}–{max(counts)}" if min(counts) != max(counts) else f"{counts[0]}"
    note = " (≤ 1 by design)" if contender.name == "paper" and contender.expected > 1 else ""
    return f"{text} of {contender.expected} {what} {'✓' if ok else '✗'}{note}", ok


def summarise(contender: Contender, sc: ScenarioFrames, peak: float) -> Figures:
    """Median, p90 and spread of the timed frames, what was found, and the track-only figures."""
    t = np.asarray(contender.times_ns, dtype=np.float64) / 1e6
    found, ok = _found(contender, sc)
    extra: Dict[str, float] = {}
    if contender.name == "track":
        tracked = np.array([isinstance(o, FrameResult) and o.tracked for o in contender.outputs])
        extra = {
            "tracked_median_ms": float(np.median(t[tracked])) if tracked.any() else math.nan,
            "all_mean_ms": float(t.mean()),
            "tracked_share": float(tracked.mean()),
        }
    return Figures(
        name=contender.name,
        median_ms=float(np.median(t)),
        p90_ms=float(np.percentile(t, 90)),
        spread_ms=(min(contender.run_medians_ns) / 1e6, max(contender.run_medians_ns) / 1e6),
        found=found,
        found_ok=ok,
        error=_errors(contender, sc),
        peak_kib=peak,
        **extra,
    )


def measure_scenario(sc: ScenarioFrames, repeats: int, aruco: Optional[Process]) -> Dict[str, Figures]:
    """Time every contender on the scenario's frames, then measure its memory; figures by name."""
    contenders = rangebearing_contenders(sc, aruco)
    run_timed(contenders, sc.frames, repeats)
    return {c.name: summarise(c, sc, peak_kib(c.process, sc.frames)) for c in contenders}
