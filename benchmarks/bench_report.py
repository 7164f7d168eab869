"""Markdown tables of a benchmark run, the targets with PASS/MISS, and the machine header."""

from __future__ import annotations

import dataclasses
import datetime
import math
import os
import platform
import resource
import subprocess
import sys
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

import cv2
import numpy as np
from bench_daemon import DaemonFigures
from bench_timing import Figures

import rangebearing

Key = Tuple[str, int]  # resolution label, landmarks in view
Stages = Dict[int, Tuple[List[Tuple[str, float]], int]]  # landmarks -> (stage rows, found)


@dataclasses.dataclass
class Run:
    """Everything one benchmark run measured."""

    resolutions: List[Tuple[int, int]]
    counts: List[int]
    frames_per_scenario: int
    repeats: int
    figures: Dict[Key, Dict[str, Figures]]
    marker_scale: Dict[Key, float]
    stage_label: str
    stages: Stages
    stage_error: str
    daemon: Optional[DaemonFigures]
    aruco_note: str


def table(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    lines = ["| " + " | ".join(headers) + " |", "|" + "|".join("---" for _ in headers) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def ms(x: float) -> str:
    return "–" if math.isnan(x) else (f"{x:.3f}" if x < 10 else f"{x:.1f}")


def ratio(a: float, b: float) -> float:
    return a / b if b > 0 and not math.isnan(a) and not math.isnan(b) else math.nan


def times(x: float) -> str:
    return "–" if math.isnan(x) else f"{x:.1f}×"


def label(w: int, h: int) -> str:
    return f"{w}×{h}"


def max_rss_mib() -> float:
    """The process's peak resident set size (ru_maxrss is KiB on Linux, bytes on macOS)."""
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return rss / (1024.0 * 1024.0) if sys.platform == "darwin" else rss / 1024.0


def per_frame_table(run: Run) -> str:
    rows = []
    for (res, n), figs in run.figures.items():
        for name in ("paper", "full", "aruco"):
            f = figs.get(name)
            if f is None:
                continue
            note = f" (markers {run.marker_scale[(res, n)]:.2f}× landmark height)" if name == "aruco" and n else ""
            rows.append([res, n, name, ms(f.median_ms), ms(f.p90_ms), f"{ms(f.spread_ms[0])}–{ms(f.spread_ms[1])}",
                         f"{1000 / f.median_ms:.0f}", f.found + note, f.error or "", f"{f.peak_kib:.0f}"])
    return table(["resolution", "N", "contender", "median ms", "p90 ms", "pass medians ms", "fps", "found per frame",
                  "worst range / bearing error", "peak alloc KiB"], rows)


def tracking_table(run: Run) -> str:
    rows = []
    for (res, n), figs in run.figures.items():
        f = figs["track"]
        rows.append([res, n, ms(f.tracked_median_ms), ms(f.all_mean_ms), ms(f.median_ms),
                     f"{100 * f.tracked_share:.0f} %", f.found, f.error, f"{f.peak_kib:.0f}"])
    return table(["resolution", "N", "tracked frames median ms", "all frames mean ms", "all frames median ms",
                  "tracked share", "found per frame", "worst range / bearing error", "peak alloc KiB"], rows)


def _get(run: Run, res: str, n: int, name: str, attr: str = "median_ms") -> float:
    f = run.figures.get((res, n), {}).get(name)
    return math.nan if f is None else getattr(f, attr)


def ratio_table(run: Run) -> str:
    rows = []
    for (res, n) in run.figures:
        full = _get(run, res, n, "full")
        rows.append([res, n, times(ratio(_get(run, res, n, "paper"), full)),
                     times(ratio(_get(run, res, n, "aruco"), full)),
                     times(ratio(full, _get(run, res, n, "track", "tracked_median_ms")))])
    return table(["resolution", "N", "paper / full", "aruco / full", "full / track (tracked frames)"], rows)


def scaling_table(run: Run) -> str:
    rows = []
    for w, h in run.resolutions:
        res, mpx = label(w, h), w * h / 1e6
        fulls = [ms(_get(run, res, n, "full")) for n in run.counts]
        flat = ratio(_get(run, res, 10, "full"), _get(run, res, 1, "full"))
        per_mpx = [ms(_get(run, res, n, "full") / mpx) for n in (1, 10) if n in run.counts]
        rows.append([res, f"{mpx:.3f}", *fulls, times(flat), *per_mpx])
    heads = [f"full ms N={n}" for n in run.counts]
    per_heads = [f"full ms/Mpx N={n}" for n in (1, 10) if n in run.counts]
    return table(["resolution", "Mpx", *heads, "full(10) / full(1)", *per_heads], rows)


def stage_table(run: Run) -> str:
    if run.stage_error:
        return f"Stage breakdown unavailable: {run.stage_error}"
    counts = sorted(run.stages)
    names = [name for name, _ in run.stages[counts[0]][0]]
    rows = []
    for name in names:
        rows.append([name, *(ms(dict(run.stages[n][0]).get(name, math.nan)) for n in counts)])
    sums = [sum(t for name, t in run.stages[n][0] if not name.startswith("Pipeline")) for n in counts]
    rows.append(["sum of the stages above", *(ms(s) for s in sums)])
    rows.append(["landmarks found", *(str(run.stages[n][1]) for n in counts)])
    return table(["stage (median ms)", *(f"N={n}" for n in counts)], rows)


def daemon_table(d: Optional[DaemonFigures]) -> str:
    if d is None:
        return "Daemon check skipped."
    return table(
        ["fps asked", "run s", "frames processed", "dropped", "bad", "achieved fps", "latency p50 ms",
         "latency p99 ms", "datagrams received", "median stage ms"],
        [[f"{d.fps_asked:.0f}", f"{d.duration_s:.1f}", f"{d.frames} / {d.frames_expected}", d.dropped, d.bad_frames,
          f"{d.achieved_fps:.1f}", f"{d.latency_ms_p50:.2f}", f"{d.latency_ms_p99:.2f}", d.received, d.stage_ms]],
    )


def _worst(run: Run, res: str, a: str, b: str, attr_b: str = "median_ms") -> Tuple[float, str, bool]:
    """Smallest a/b over N = 1, 5, 10 (the worst case), the per-N figures, and whether both found all."""
    per, ok = [], True
    for n in (n for n in run.counts if n > 0):
        per.append((n, ratio(_get(run, res, n, a), _get(run, res, n, b, attr_b))))
        for name in (a, b):
            f = run.figures[(res, n)].get(name)
            ok = ok and (f is None or name == "paper" or f.found_ok)
    worst = min((r for _, r in per), default=math.nan)
    detail = ", ".join(f"N={n}: {times(r)}" for n, r in per)
    return worst, f"{times(worst)} (worst of {detail})", ok


def _verdict(passed: bool, valid: bool = True, available: bool = True) -> str:
    if not available:
        return "n/a"
    if not valid:
        return "INVALID (a contender missed what it should find)"
    return "PASS" if passed else "MISS"


def targets_table(run: Run) -> str:
    w, h = (640, 480) if (640, 480) in run.resolutions else run.resolutions[0]
    res = label(w, h)
    rows = []
    r, text, ok = _worst(run, res, "paper", "full")
    rows.append([f"full ≥ 30× faster than paper ({res})", text, _verdict(r >= 30, ok, not math.isnan(r))])
    r, text, ok = _worst(run, res, "aruco", "full")
    rows.append([f"full ≥ 2× faster than ArUco ({res})", text if not math.isnan(r) else run.aruco_note,
                 _verdict(r >= 2, ok, not math.isnan(r))])
    r, text, ok = _worst(run, res, "full", "track", "tracked_median_ms")
    rows.append([f"tracked frames ≥ 5× faster than full ({res})", text, _verdict(r >= 5, ok, not math.isnan(r))])
    flat = ratio(_get(run, res, 10, "full"), _get(run, res, 1, "full"))
    rows.append([f"full(10) ≤ 1.5× full(1) ({res})", times(flat), _verdict(flat <= 1.5, True, not math.isnan(flat))])
    slope, text = linearity(run)
    rows.append(["near-linear in pixel count: log-log slope of full(N=1) time vs pixels ≤ 1.2", text,
                 _verdict(slope <= 1.2, True, not math.isnan(slope))])
    d = run.daemon
    if d is None:
        rows.append(["daemon keeps up: 0 dropped, p99 ≤ 5 ms", "skipped", "n/a"])
    else:
        ok = d.dropped == 0 and d.latency_ms_p99 <= 5.0 and d.frames == d.frames_expected and d.exit_code == 0
        rows.append([f"daemon at {d.fps_asked:.0f} fps: 0 dropped, p99 ≤ 5 ms",
                     f"{d.frames}/{d.frames_expected} frames, {d.dropped} dropped, p99 {d.latency_ms_p99:.2f} ms",
                     _verdict(ok)])
    return table(["target", "figure", "result"], rows)


def linearity(run: Run) -> Tuple[float, str]:
    """Least-squares slope of log(full time, N=1) against log(pixels) over the resolutions measured."""
    pts = [(math.log(w * h), math.log(_get(run, label(w, h), 1, "full"))) for w, h in run.resolutions]
    pts = [p for p in pts if not math.isnan(p[1])]
    if len(pts) < 2:
        return math.nan, "needs two resolutions"
    x, y = np.array(pts).T
    slope = float(np.polyfit(x, y, 1)[0])
    per = ", ".join(f"{label(w, h)} {ms(_get(run, label(w, h), 1, 'full') / (w * h / 1e6))}"
                    for w, h in run.resolutions)
    return slope, f"slope {slope:.2f} (ms/Mpx: {per})"


def render(run: Run) -> str:
    """The markdown body: settings, every table, the targets."""
    return "\n\n".join([
        f"Frames per scenario: {run.frames_per_scenario} (cycled), timed passes: {run.repeats} after one warm-up "
        f"pass, one core (`cv2.setNumThreads(1)`), times are per frame. {run.aruco_note}",
        "## Per-frame time (independent frames)", per_frame_table(run),
        "## Tracking (consecutive frames)", tracking_table(run),
        "## Ratios (same run)", ratio_table(run),
        "## Landmark count and pixel count (full)", scaling_table(run),
        f"## Stage breakdown (full-frame scan, {run.stage_label})", stage_table(run),
        "## Daemon keep-up", daemon_table(run.daemon),
        "## Memory", f"Peak tracemalloc allocation per frame is in the tables above (numpy and OpenCV outputs; "
        f"not OpenCV's internal buffers). Process max RSS at the end: {max_rss_mib():.0f} MiB (includes the "
        "synthetic renderer, so far above what the daemon needs).",
        "## Targets", targets_table(run),
    ]) + "\n"


def _cpu_model() -> str:
    try:
        info = Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return platform.processor() or platform.machine()
    for key in ("model name", "Model", "Hardware"):
        for line in info.splitlines():
            if line.split(":")[0].strip() == key:
                return line.split(":", 1)[1].strip()
    return platform.machine()


def _git(root: Path, *args: str) -> str:
    # GIT_OPTIONAL_LOCKS=0: read only, git status must not refresh the index
    env = dict(os.environ, GIT_OPTIONAL_LOCKS="0")
    try:
        out = subprocess.run(["git", *args], cwd=root, capture_output=True, text=True, timeout=5, check=False, env=env)
    except (OSError, subprocess.SubprocessError):
        return ""
    return out.stdout.strip() if out.returncode == 0 else ""


def _git_commit(root: Path) -> str:
    """The commit measured, noting uncommitted changes to the library."""
    commit = _git(root, "rev-parse", "--short", "HEAD") or "unknown"
    dirty = _git(root, "status", "--porcelain", "--untracked-files=no", "--", "src")
    return f"{commit} + uncommitted changes in src/" if dirty else commit


def machine_header(command: str) -> str:
    """Where and how the figures were taken."""
    cores = os.cpu_count()
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else cores
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return "\n".join([
        "# rangebearing speed benchmark",
        "",
        f"- Date: {now}",
        f"- Command: `{command}`",
        f"- CPU: {_cpu_model()} ({cores} cores, {usable} usable; the benchmark uses one)",
        f"- OS: {platform.platform()}",
        f"- Python {platform.python_version()}, numpy {np.__version__}, OpenCV {cv2.__version__}, "
        f"rangebearing {rangebearing.__version__} (commit {_git_commit(Path(__file__).resolve().parents[1])})",
        "",
    ])
