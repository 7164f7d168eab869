"""Issue 8's acceptance table in one command: calibrate, render every set, replay it against truth.

Usage::

    python benchmarks/acceptance.py [--seed-base 6100] [--frames 60] [--seeds-per-set K]
                                    [--sets occlusion,crowd,...] [--workdir DIR] [--json FILE]
                                    [--config FILE] [--jobs N]

What it does, the way a user measures (``rangebearing calibrate``, then ``rangebearing replay
--truth``, with ``--track`` for the moving crowd), but in-process on the same library calls:

1. renders the calibration set (``multi``, ``--cal-seed`` 5151, ``--cal-frames`` 60) and keeps
   the frames whose landmarks are all 0.2–1.4 m away, as issue 8 calibrates;
2. fits the model with :func:`~rangebearing.evaluation.calibrate.calibrate_checked` (what
   ``calibrate`` runs) and writes the config (``--config FILE`` skips both steps);
3. renders every set (set *i* in :data:`SETS` order gets seed ``seed_base + i``: the default
   6100 gives last session's 6101–6109; ``crowd-moving`` is 5× ``--frames`` long, 300 by
   default) and replays it through :class:`~rangebearing.Pipeline` from the files on disk;
   ``--seeds-per-set K`` renders K seeds of each set (``seed_base + i + 20·k``) and pools their
   readings in the set's row (ids are counted per sequence, then summed);
4. prints one Markdown table, every cell that misses its issue-8 bound marked ✗ (and the error of
   the reported ``visible`` against the truth's visible fraction, which has no bound).

Rendered sets are cached in ``--workdir`` (keyed by preset, seed, frames, format and a hash of
the renderer's source, so a changed renderer renders afresh); without it a temporary folder
is used and removed. ``--jobs 2`` renders and replays two sets (or seeds) at a time, the
longest first.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import multiprocessing
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple

os.environ.setdefault("OMP_NUM_THREADS", "1")

from rangebearing import Pipeline, load_config
from rangebearing.cli.common import aligned_truth, save_config
from rangebearing.evaluation.calibrate import calibrate_checked
from rangebearing.evaluation.identity import id_report
from rangebearing.evaluation.match import accuracy
from rangebearing.evaluation.truth import read_truth, write_truth
from rangebearing.sources.recorded import iter_recorded
from rangebearing.synth import write_dataset

# name, image format, frames as a multiple of --frames, tracked; set i (1-based) gets seed base + i
SETS: Tuple[Tuple[str, str, int, bool], ...] = (
    ("occlusion", "png", 1, False),
    ("touching", "png", 1, False),
    ("crowd", "png", 1, False),
    ("far", "png", 1, False),
    ("lighting", "png", 1, False),
    ("paper", "png", 1, False),
    ("wide", "jpg", 1, False),
    ("clutter", "jpg", 1, False),
    ("multi", "png", 1, False),
    ("crowd-moving", "png", 5, True),
    ("photoreal", "png", 1, False),  # not in the default --sets: the Pi camera's lens and ISP (synth docs)
    ("photoreal-crowd", "png", 1, False),
    ("rooms", "png", 1, False),  # lighting frames in an all-red or all-blue room (appended: earlier seeds unchanged)
    ("photoreal-alt", "png", 1, False),  # photoreal scenes through another camera and paint (appended, as rooms)
    ("mimic", "png", 1, False),  # not in the default --sets: red/white/blue things that are no landmark (false only)
)
DEFAULT_SETS = tuple(s[0] for s in SETS if not s[0].startswith("photoreal") and s[0] != "mimic")
# issue 8: found share of findable landmarks; paper/wide/clutter/multi keep the core issue's bounds
MIN_FOUND = {"occlusion": 97.0, "touching": 97.0, "crowd": 97.0, "far": 99.0, "lighting": 97.0,
             "paper": 100.0, "wide": 97.0, "clutter": 100.0, "multi": 97.0,
             "rooms": 97.0, "photoreal": 97.0, "photoreal-crowd": 97.0, "photoreal-alt": 97.0}
MAX_FALSE_PER_200 = 1.0
MAX_RANGE_PCT = (1.0, 3.0)  # mean, p95
MAX_BEARING_DEG = (0.1, 0.3)
COVER_PCT = (90.0, 98.0)
MAX_SWITCHES_PER_1000 = 1.0
CAL_RANGE_M = (0.2, 1.4)
SEED_STRIDE = 20  # set i's k-th seed is BASE + i + k * SEED_STRIDE (more than the sets: no seed is used twice)
SYNTH_DIR = Path(__file__).resolve().parents[1] / "src" / "rangebearing" / "synth"


def renderer_hash() -> str:
    """A short hash of the renderer's source: a changed renderer never reuses a cached set."""
    h = hashlib.sha1()
    for p in sorted(SYNTH_DIR.glob("*.py")):
        h.update(p.name.encode() + p.read_bytes())
    return h.hexdigest()[:10]


def rendered(workdir: Path, preset: str, seed: int, frames: int, fmt: str, tag: str) -> Path:
    """The folder holding this set, rendered now unless a complete copy is already there."""
    out = workdir / f"{preset}-s{seed}-n{frames}-{fmt}-{tag}"
    if (out / ".complete").exists():
        return out
    if out.exists():
        shutil.rmtree(out)
    write_dataset(out, frames, seed, preset, fmt)
    (out / ".complete").write_text("")
    return out


def set_seeds(base: int, index: int, k: int) -> List[int]:
    """The ``k`` seeds of set ``index`` (1-based, table order)."""
    return [base + index + j * SEED_STRIDE for j in range(k)]


def calibration_frames(workdir: Path, seed: int, frames: int, tag: str) -> Path:
    """The calibration set: ``multi`` frames whose landmarks all lie 0.2–1.4 m away (a truth of those)."""
    src = rendered(workdir, "multi", seed, frames, "png", tag)
    rows = read_truth(src / "truth.csv")
    keep = {name for name, rs in rows.items() if rs and all(CAL_RANGE_M[0] <= r.range_m <= CAL_RANGE_M[1]
                                                            for r in rs)}
    path = src / "truth-cal.csv"
    write_truth(path, [r for name in sorted(keep) for r in rows[name]])
    return path


def calibrate(workdir: Path, seed: int, frames: int, tag: str) -> Tuple[Path, str]:
    """Fit the model as ``rangebearing calibrate`` does; returns the config written and a summary."""
    truth_path = calibration_frames(workdir, seed, frames, tag)
    folder = truth_path.parent
    truth = aligned_truth(folder, truth_path)

    def frames_iter() -> Any:  # only the frames in range: a frame with a landmark beyond 1.4 m is left out
        return ((name, image, truth[name]) for name, image in iter_recorded(folder) if truth.get(name))

    cfg, fit, check, _ = calibrate_checked(frames_iter, load_config(None))
    out = workdir / f"cal-s{seed}-n{frames}-{tag}.yaml"
    save_config(cfg, out, f"written by benchmarks/acceptance.py (calibrate, multi seed {seed}, 0.2-1.4 m)")
    lo, hi = cfg.model.envelope_range_m
    note = (f"calibrated on {len(fit.residuals)} landmarks ({len({r.frame for r in fit.residuals})} frames, "
            f"{lo:.2f}-{hi:.2f} m): range residual mean {fit.range_err_pct_mean:.2f} %, "
            f"bearing {fit.bearing_err_deg_mean:.3f}°; {check.message}")
    return out, note


def evaluate(job: Tuple[str, str, int, int, bool, str, str, str]) -> Dict[str, Any]:
    """Render (or reuse) one set of one seed and replay it against its truth: its readings, matched later."""
    name, fmt, seed, frames, tracked, workdir, tag, config = job
    start = time.perf_counter()
    folder = rendered(Path(workdir), name, seed, frames, fmt, tag)
    rendered_s = time.perf_counter() - start
    truth = aligned_truth(folder, folder / "truth.csv")
    pipe = Pipeline(load_config(config).pipeline, track=tracked)
    evaluated = [(n, pipe.process(img).landmarks, truth.get(n, [])) for n, img in iter_recorded(folder)]
    part: Dict[str, Any] = {"set": name, "seed": seed, "evaluated": evaluated, "render_s": rendered_s,
                            "replay_s": time.perf_counter() - start - rendered_s}
    if tracked:  # per sequence: ids are never compared across two runs
        ids = id_report((found, rows) for _, found, rows in evaluated)
        part["ids"] = {"switches": ids.switches, "landmark_frames": ids.landmark_frames, "returns": ids.returns,
                       "returns_kept": ids.returns_kept, "untracked": ids.untracked}
    return part


def merged(parts: Sequence[Dict[str, Any]]) -> Dict[str, Any]:
    """One set's row from its seeds' parts: the readings of every seed pooled, ids summed per sequence."""
    evaluated = [e for p in parts for e in p["evaluated"]]
    rep, _ = accuracy(evaluated)
    row: Dict[str, Any] = {
        "set": parts[0]["set"], "seed": ",".join(str(p["seed"]) for p in parts), "frames": rep.frames,
        "empty_frames": rep.empty_frames, "findable": rep.findable, "found_pct": 100.0 * rep.findable_rate,
        "false": rep.false_landmarks, "false_on_empty": rep.false_on_empty,
        "false_per_200": 200.0 * rep.false_landmarks / max(rep.frames, 1),
        "range_mean_pct": rep.range_err_pct_mean, "range_p95_pct": rep.range_err_pct_p95,
        "bearing_mean_deg": rep.bearing_err_deg_mean, "bearing_p95_deg": rep.bearing_err_deg_p95,
        "range_cover_pct": 100.0 * rep.range_cover, "bearing_cover_pct": 100.0 * rep.bearing_cover,
        "visible_err_mean": rep.visible_err_mean, "visible_err_p95": rep.visible_err_p95,
        "render_s": sum(p["render_s"] for p in parts), "replay_s": sum(p["replay_s"] for p in parts),
    }
    if "ids" in parts[0]:
        ids = {k: sum(p["ids"][k] for p in parts) for k in parts[0]["ids"]}
        row.update(ids, switches_per_1000=1000.0 * ids["switches"] / max(ids["landmark_frames"], 1))
    row["misses"] = misses(row)
    return row


def misses(row: Dict[str, Any]) -> List[str]:
    """The row's fields that miss their issue-8 bound."""
    out = []
    if row["set"] in MIN_FOUND and row["found_pct"] < MIN_FOUND[row["set"]]:
        out.append("found_pct")
    if row["false_on_empty"] > 0:
        out.append("false_on_empty")
    if row["false_per_200"] > MAX_FALSE_PER_200:
        out.append("false_per_200")
    for key, bound in (("range_mean_pct", MAX_RANGE_PCT[0]), ("range_p95_pct", MAX_RANGE_PCT[1]),
                       ("bearing_mean_deg", MAX_BEARING_DEG[0]), ("bearing_p95_deg", MAX_BEARING_DEG[1])):
        if not row[key] <= bound:  # NaN (nothing found) misses too
            out.append(key)
    for key in ("range_cover_pct", "bearing_cover_pct"):
        if not COVER_PCT[0] <= row[key] <= COVER_PCT[1]:
            out.append(key)
    if "switches_per_1000" in row:
        if row["switches_per_1000"] > MAX_SWITCHES_PER_1000:
            out.append("switches_per_1000")
        if row["returns_kept"] < row["returns"] or row["untracked"]:
            out.append("returns_kept")
    return out


def _cell(row: Dict[str, Any], key: str, fmt: str) -> str:
    value = row.get(key)
    if value is None:
        return ""
    text = "-" if isinstance(value, float) and math.isnan(value) else format(value, fmt)
    return text + (" ✗" if key in row["misses"] else "")


HEADER = ("| set | seed | frames (empty) | findable | found % | false (on empty) | false / 200 fr "
          "| range err mean / p95 % | bearing err mean / p95 ° | 2σ cover range / bearing % "
          "| visible err mean / p95 | id switches / 1000 | returns kept |")


def table(rows: Sequence[Dict[str, Any]]) -> str:
    """The Markdown table, ✗ after every figure that misses its bound."""
    lines = [HEADER, "|" + "---|" * HEADER.count(" | ") + "---|"]
    for r in rows:
        returns = f"{r['returns_kept']} of {r['returns']}" if "returns" in r else ""
        if "returns_kept" in r["misses"]:
            returns += " ✗"
        lines.append(" | ".join([
            f"| {r['set']}", str(r["seed"]), f"{r['frames']} ({r['empty_frames']})", str(r["findable"]),
            _cell(r, "found_pct", ".1f"), f"{r['false']} ({_cell(r, 'false_on_empty', 'd')})",
            _cell(r, "false_per_200", ".1f"),
            f"{_cell(r, 'range_mean_pct', '.2f')} / {_cell(r, 'range_p95_pct', '.2f')}",
            f"{_cell(r, 'bearing_mean_deg', '.3f')} / {_cell(r, 'bearing_p95_deg', '.3f')}",
            f"{_cell(r, 'range_cover_pct', '.1f')} / {_cell(r, 'bearing_cover_pct', '.1f')}",
            f"{_cell(r, 'visible_err_mean', '.3f')} / {_cell(r, 'visible_err_p95', '.3f')}",
            _cell(r, "switches_per_1000", ".2f"), returns + " |",
        ]))
    return "\n".join(lines)


def bounds_text() -> str:
    return (f"Bounds (issue 8): found >= 97 % (far 99 %; paper/clutter 100 %, wide/multi 97 % from the core issue), "
            f"false <= {MAX_FALSE_PER_200:g} per 200 frames and none on empty frames, range error mean <= "
            f"{MAX_RANGE_PCT[0]:g} % / p95 <= {MAX_RANGE_PCT[1]:g} %, bearing mean <= {MAX_BEARING_DEG[0]:g}° / "
            f"p95 <= {MAX_BEARING_DEG[1]:g}°, 2σ cover {COVER_PCT[0]:g}-{COVER_PCT[1]:g} % in each, "
            f"<= {MAX_SWITCHES_PER_1000:g} id switch per 1000 landmark-frames and every return within 15 frames "
            "keeps its id. ✗ marks a miss.")


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    names = [s[0] for s in SETS]
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seed-base", type=int, default=6100, help="set i (1-based, table order) gets seed BASE+i")
    p.add_argument("--frames", type=int, default=60, help="frames per set (crowd-moving: 5x); default 60")
    p.add_argument("--seeds-per-set", type=int, default=1, metavar="K",
                   help=f"seeds pooled in each set's row: BASE+i, BASE+i+{SEED_STRIDE}, ... (default 1)")
    p.add_argument("--sets", default=",".join(DEFAULT_SETS),
                   help=f"comma-separated subset of {','.join(names)} (default: all but photoreal*)")
    p.add_argument("--workdir", help="cache folder for the rendered sets and the config (reused when present)")
    p.add_argument("--json", metavar="FILE", help="also write the rows (raw figures, misses) as JSON")
    p.add_argument("--config", metavar="FILE", help="replay with this config; skip the calibration")
    p.add_argument("--cal-seed", type=int, default=5151, help="seed of the multi calibration set (default 5151)")
    p.add_argument("--cal-frames", type=int, default=60, help="frames rendered for calibration (default 60)")
    p.add_argument("--jobs", type=int, default=1, help="sets rendered and replayed at once (default 1)")
    args = p.parse_args(argv)
    chosen = [s.strip() for s in args.sets.split(",") if s.strip()]
    unknown = [s for s in chosen if s not in names]
    if unknown or not chosen:
        p.error(f"--sets: unknown {', '.join(unknown) or '(none given)'}; choose from {', '.join(names)}")
    if args.frames < 1 or args.cal_frames < 1 or args.jobs < 1 or args.seeds_per_set < 1:
        p.error("--frames, --cal-frames, --seeds-per-set and --jobs must be >= 1")
    if args.config and not Path(args.config).is_file():
        p.error(f"--config: no such file {args.config}")
    args.sets = chosen
    return args


def main(argv: Optional[Sequence[str]] = None) -> int:
    args = parse_args(argv)
    start = time.perf_counter()
    temp = None if args.workdir else tempfile.mkdtemp(prefix="rb-acceptance-")
    workdir = Path(args.workdir or temp)
    workdir.mkdir(parents=True, exist_ok=True)
    tag = renderer_hash()
    try:
        if args.config:
            config, note = Path(args.config), f"config {args.config} (not calibrated here)"
        else:
            config, note = calibrate(workdir, args.cal_seed, args.cal_frames, tag)
        cal_s = time.perf_counter() - start
        jobs = [(name, fmt, seed, args.frames * k, tracked, str(workdir), tag, str(config))
                for i, (name, fmt, k, tracked) in enumerate(SETS, start=1) if name in args.sets
                for seed in set_seeds(args.seed_base, i, args.seeds_per_set)]
        # the longest jobs first, so two workers end together
        order = sorted(range(len(jobs)), key=lambda j: -jobs[j][3] * (8 if jobs[j][0].startswith("photoreal") else 1))
        if args.jobs > 1:
            with multiprocessing.get_context("spawn").Pool(min(args.jobs, len(jobs))) as pool:
                done = dict(zip(order, pool.map(evaluate, [jobs[j] for j in order], chunksize=1)))
        else:
            done = {j: evaluate(jobs[j]) for j in order}
        parts = [done[j] for j in range(len(jobs))]
        rows = [merged([p for p in parts if p["set"] == name]) for name in dict.fromkeys(p["set"] for p in parts)]
    finally:
        if temp:
            shutil.rmtree(temp, ignore_errors=True)
    wall = time.perf_counter() - start
    print(table(rows))
    print()
    print(bounds_text())
    print(f"{note}.")
    print(f"Wall time {wall:.0f} s (calibration {cal_s:.0f} s; rendering {sum(r['render_s'] for r in rows):.0f} s, "
          f"replay {sum(r['replay_s'] for r in rows):.0f} s summed over sets; --jobs {args.jobs}).")
    cmd = "python benchmarks/acceptance.py " + " ".join(sys.argv[1:] if argv is None else argv)
    print(f"Command: `{cmd.strip()}`")
    if args.json:
        Path(args.json).write_text(json.dumps({"command": cmd.strip(), "calibration": note, "wall_s": wall,
                                               "rows": rows}, indent=1, default=float) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
