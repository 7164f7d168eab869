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
from typing import Dict, List, Sequence, Tuple

import cv2
import numpy as np
from bench_daemon import DaemonFigures
from bench_timing import Figures

import rangebearing

Key = Tuple[str, str]  # resolution label, scene ("N=5" for the clean scenes, else the preset's name)
Stages = Dict[int, Tuple[List[Tuple[str, float]], int]]  # landmarks -> (stage rows, found)
MARKERS = ("aruco", "apriltag d2", "apriltag d1")


@dataclasses.dataclass
class Run:
    """Everything one benchmark run measured."""

    resolutions: List[Tuple[int, int]]
    counts: List[int]
    frames_per_scenario: int
    repeats: int
    passes: int
    gap_s: Tuple[float, float]
    figures: Dict[Key, Dict[str, Figures]]
    marker_scale: Dict[Key, float]
    truth_counts: Dict[Key, float]  # mean landmarks to find per frame
    stage_label: str
    stages: Stages
    stage_error: str
    daemon: List[DaemonFigures]
    notes: List[str]


def clean(n: int) -> str:
    return f"N={n}"


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


def _get(run: Run, key: Key, name: str, attr: str = "cold_ms") -> float:
    f = run.figures.get(key, {}).get(name)
    return math.nan if f is None else getattr(f, attr)


def per_frame_table(run: Run) -> str:
    rows = []
    for (res, scene), figs in run.figures.items():
        for name in ("paper", "full", "full yuv", *MARKERS):
            f = figs.get(name)
            if f is None:
                continue
            scale = run.marker_scale.get((res, scene), 1.0)
            note = f" (markers {scale:.2f}× landmark height)" if name in MARKERS and f.found[0] != "0" else ""
            rows.append([res, scene, name, ms(f.cold_ms), ms(f.cold_p90_ms), ms(f.warm_ms),
                         times(ratio(f.cold_ms, f.warm_ms)), ms(f.wall_cold_ms), ms(f.wall_cold_p99_ms),
                         f.found + note, f.error, f"{f.peak_kib:.0f}"])
    return table(["resolution", "scene", "contender", "cold CPU ms", "cold p90", "warm CPU ms", "cold / warm",
                  "cold wall ms", "cold wall p99", "found per frame", "worst range / bearing error",
                  "peak alloc KiB"], rows)


def tracking_table(run: Run) -> str:
    rows = []
    for key, figs in run.figures.items():
        if "track" not in figs:
            continue
        f, full = figs["track"], figs["full"]
        rows.append([key[0], key[1], ms(f.tracked_cold_ms), ms(f.tracked_warm_ms), ms(f.all_cold_mean_ms),
                     f"{100 * f.tracked_share:.0f} %", ms(full.cold_ms), times(ratio(full.cold_ms, f.tracked_cold_ms)),
                     times(ratio(full.warm_ms, f.tracked_warm_ms)), f.found, f.error])
    return table(["resolution", "scene", "tracked frames cold ms", "tracked warm ms", "all frames cold mean ms",
                  "tracked share", "full cold ms", "full / tracked (cold)", "full / tracked (warm)",
                  "found per frame", "worst range / bearing error"], rows)


def ratio_table(run: Run) -> str:
    rows = []
    for key in run.figures:
        full, full_w = _get(run, key, "full"), _get(run, key, "full", "warm_ms")
        cells = []
        for name in ("paper", *MARKERS):
            cold, warm = ratio(_get(run, key, name), full), ratio(_get(run, key, name, "warm_ms"), full_w)
            cells.append(f"{times(cold)} ({times(warm)})")
        yuv = ratio(full, _get(run, key, "full yuv"))
        rows.append([key[0], key[1], *cells, times(yuv)])
    return table(["resolution", "scene", *(f"{n} / full, cold (warm)" for n in ("paper", *MARKERS)),
                  "full / full yuv, cold"], rows)


def scaling_table(run: Run) -> str:
    rows = []
    for w, h in run.resolutions:
        res, mpx = label(w, h), w * h / 1e6
        fulls = [ms(_get(run, (res, clean(n)), "full")) for n in run.counts]
        flat = ratio(_get(run, (res, clean(10)), "full"), _get(run, (res, clean(1)), "full"))
        rows.append([res, f"{mpx:.3f}", *fulls, times(flat), ms(_get(run, (res, clean(1)), "full") / mpx)])
    return table(["resolution", "Mpx", *(f"full cold ms N={n}" for n in run.counts), "full(10) / full(1)",
                  "cold ms/Mpx N=1"], rows)


def stage_table(run: Run) -> str:
    if run.stage_error:
        return f"Stage breakdown unavailable: {run.stage_error}"
    if not run.stages:
        return "Stage breakdown not run."
    counts = sorted(run.stages)
    names = [name for name, _ in run.stages[counts[0]][0]]
    rows = [[name, *(ms(dict(run.stages[n][0]).get(name, math.nan)) for n in counts)] for name in names]
    sums = [sum(t for name, t in run.stages[n][0] if not name.startswith(("Pipeline", "yuv"))) for n in counts]
    rows.append(["sum of the BGR stages above", *(ms(s) for s in sums)])
    rows.append(["landmarks found", *(str(run.stages[n][1]) for n in counts)])
    return table(["stage (median CPU ms, warm)", *(f"N={n}" for n in counts)], rows)


def daemon_table(runs: Sequence[DaemonFigures]) -> str:
    if not runs:
        return "Daemon runs skipped."
    rows = []
    for d in runs:
        if d.error:
            rows.append([f"{d.fps_asked:.0f}", "failed: " + d.error.replace("\n", " ")[:300], *([""] * 12)])
            continue
        pipe = getattr(d, "pipeline_cpu_ms", math.nan)
        rows.append([f"{d.fps_asked:.0f}", f"{d.startup_s:.2f}", f"{d.duration_s:.1f}",
                     f"{d.received} / {d.frames_expected}", d.dropped, d.seq_gaps, f"{d.cpu_pct:.2f}",
                     f"{d.cpu_ms_per_frame:.2f}", f"{d.latency_ms_p50:.2f} / {d.latency_ms_p99:.2f} / "
                     f"{d.latency_ms_max:.2f}", f"{d.rss_mib:.0f} / {d.rss_peak_mib:.0f}", d.exit_code,
                     f"{pipe:.2f} ({getattr(d, 'tracked_pct', math.nan):.0f} %)",
                     f"{d.cpu_ms_per_frame - pipe:.2f}", f"{getattr(d, 'clip_mib', math.nan):.0f}"])
    return table(["fps asked", "start-up s (to 1st datagram)", "window s", "datagrams / frames due", "dropped",
                  "seq gaps", "CPU % of a core", "CPU ms per frame", "latency p50 / p99 / max ms",
                  "RSS / peak MiB", "exit", "pipeline CPU ms per frame (tracked)", "rest of the daemon ms per frame",
                  "recorded clip MiB (page cache, not RSS)"], rows) + (
        "\n\nThe pipeline's CPU is the daemon's own figure (its final log line, all frames of the run); "
        "the rest is the daemon around it (source, encoding, sending, stats). Start-up runs with the "
        "package's bytecode compiled beforehand, as pip installs it. The recorded clip is decoded once "
        "(BGR and its YUV420, as a camera hands over decoded buffers) into a temporary file's page cache, "
        "mapped in only while a frame is in use: it is not in the RSS; a camera source holds none of it.")


def _valid(run: Run, key: Key, names: Sequence[str]) -> bool:
    for name in names:
        f = run.figures.get(key, {}).get(name)
        if f is not None and name != "paper" and not f.found_ok:
            return False
    return True


def _worst(run: Run, res: str, a: str, b: str, attr_b: str = "cold_ms", ns=(1, 5, 10)) -> Tuple[float, str, bool]:
    """Smallest a/b (cold) over the clean scenes N in ``ns`` (the worst case), the per-N figures, and validity."""
    per, ok = [], True
    for n in (n for n in ns if n in run.counts):
        key = (res, clean(n))
        per.append((n, ratio(_get(run, key, a), _get(run, key, b, attr_b))))
        ok = ok and _valid(run, key, (a, b))
    worst = min((r for _, r in per), default=math.nan)
    detail = ", ".join(f"N={n}: {times(r)}" for n, r in per)
    return worst, f"{times(worst)} (worst of {detail})", ok


def _verdict(passed: bool, valid: bool = True, available: bool = True, by: str = "") -> str:
    if not available:
        return "n/a"
    if not valid:
        return "INVALID (a contender missed what it should find)"
    return "PASS" if passed else f"MISS{' by ' + by if by else ''}"


def _short(r: float, goal: float) -> str:
    return f"{100 * (1 - r / goal):.0f} %" if not math.isnan(r) and r < goal else ""


def target_res(run: Run) -> str:
    w, h = (640, 480) if (640, 480) in run.resolutions else run.resolutions[0]
    return label(w, h)


def targets_table(run: Run) -> str:
    res = target_res(run)
    rows = []
    for a, goal in (("paper", 50.0), ("aruco", 3.0), ("apriltag d2", 10.0)):
        r, text, ok = _worst(run, res, a, "full")
        rows.append([f"full ≥ {goal:.0f}× faster than {a}, N = 1, 5, 10 ({res}, cold CPU)", text,
                     _verdict(r >= goal, ok, not math.isnan(r), _short(r, goal))])
    for n, goal in ((1, 4.0), (10, 3.0)):
        r, text, ok = _worst(run, res, "full", "track", "tracked_cold_ms", ns=(n,))
        rows.append([f"tracked frames ≥ {goal:.0f}× cheaper than full at N = {n} ({res}, cold CPU)", text,
                     _verdict(r >= goal, ok, not math.isnan(r), _short(r, goal))])
    for key in run.figures:
        if key[0] != res or key[1].startswith("N=") or key[1] == "sample":
            continue
        n = min((c for c in run.counts if c > 0), key=lambda c: abs(c - run.truth_counts[key]), default=1)
        r = ratio(_get(run, key, "full"), _get(run, (res, clean(n)), "full"))
        ok = _valid(run, key, ("full",))
        rows.append([f"{key[1]} frame ≤ 2× a clean frame (full, cold CPU; clean N={n})", times(r),
                     _verdict(r <= 2.0, ok, not math.isnan(r), f"{100 * (r / 2 - 1):.0f} %")])
    for d in run.daemon:
        if d.error:
            rows.append([f"daemon at {d.fps_asked:.0f} fps", d.error[:120], "MISS (failed)"])
        elif d.fps_asked <= 30:
            rows.append([f"daemon at {d.fps_asked:.0f} fps ≤ 2 % of a core", f"{d.cpu_pct:.2f} %",
                         _verdict(d.cpu_pct <= 2.0, by=f"{d.cpu_pct / 2:.1f}×")])
        else:
            ok = d.dropped == 0 and d.seq_gaps == 0 and d.received >= d.frames_expected - 1 and d.latency_ms_p99 <= 3
            rows.append([f"daemon at {d.fps_asked:.0f} fps: no drop, p99 ≤ 3 ms",
                         f"{d.received}/{d.frames_expected} datagrams, {d.dropped} dropped, p99 "
                         f"{d.latency_ms_p99:.2f} ms", _verdict(ok)])
    if run.daemon:
        worst = max((d.startup_s for d in run.daemon if not d.error), default=math.nan)
        rows.append(["start-up to the first datagram ≤ 0.3 s", f"{worst:.2f} s (slowest run)",
                     _verdict(worst <= 0.3, True, not math.isnan(worst), f"{worst / 0.3:.1f}×")])
    return table(["target", "figure", "result"], rows)


def render(run: Run) -> str:
    """The markdown body: settings, every table, the targets."""
    lo, hi = run.gap_s
    return "\n\n".join([
        f"Frames per scenario: {run.frames_per_scenario}. **Cold and paced** (the headline): {run.passes} passes, "
        f"frame by frame, contenders in shuffled order, each call after a sleep of {1e3 * lo:.0f}–{1e3 * hi:.0f} ms. "
        f"**Warm**: one untimed pass, then {run.repeats} back-to-back passes per contender. Times are CPU time of "
        "the calling thread per frame (wall time where named), one core (`sched_setaffinity`, "
        "`cv2.setNumThreads(1)`, one AprilTag thread). " + " ".join(run.notes),
        "## Per-frame CPU time, cold and warm", per_frame_table(run),
        "## Tracking (consecutive frames)", tracking_table(run),
        "## Ratios (same run; cold, warm in brackets)", ratio_table(run),
        "## Landmark count and pixel count (full, cold)", scaling_table(run),
        f"## Stage breakdown (full-frame scan, {run.stage_label})", stage_table(run),
        "## Daemon (`rangebearing run` subprocess, paced recording)", daemon_table(run.daemon),
        "## Memory", f"Peak tracemalloc allocation per frame is in the first table (numpy and OpenCV outputs; "
        f"not OpenCV's internal buffers). The daemon's RSS is in its table. The benchmark process's max RSS: "
        f"{max_rss_mib():.0f} MiB (includes the synthetic renderer).",
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


def _load() -> str:
    try:
        return Path("/proc/loadavg").read_text().split(" ")[0]
    except OSError:
        return "?"


def machine_header(command: str, extra: Sequence[str] = ()) -> str:
    """Where and how the figures were taken."""
    cores = os.cpu_count()
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else cores
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return "\n".join([
        "# rangebearing speed benchmark",
        "",
        f"- Date: {now}",
        f"- Command: `{command}`",
        f"- CPU: {_cpu_model()} ({cores} cores, {usable} usable; the benchmark pins itself to one)",
        f"- Load average (1 min) at the end: {_load()}",
        f"- OS: {platform.platform()}",
        f"- Python {platform.python_version()}, numpy {np.__version__}, OpenCV {cv2.__version__}, "
        f"rangebearing {rangebearing.__version__} (commit {_git_commit(Path(__file__).resolve().parents[1])})",
        *(f"- {e}" for e in extra),
        "",
    ])
