"""The speed benchmark runs end to end (``--quick``) and its helpers place frames honestly.

No timing is asserted here: the speed targets live in the benchmark's own
printed figures (benchmarks/RESULTS.md), never in unit tests.
"""

from __future__ import annotations

import importlib
import math
import subprocess
import sys
from pathlib import Path
from types import ModuleType
from typing import Dict, List, Tuple

import pytest

from rangebearing import Config
from rangebearing.synth import Scene, landmark_bbox_px

REPO = Path(__file__).resolve().parents[1]
BENCH_DIR = REPO / "benchmarks"
HEADINGS = (
    "## Per-frame time (independent frames)",
    "## Tracking (consecutive frames)",
    "## Ratios (same run)",
    "## Landmark count and pixel count (full)",
    "## Stage breakdown",
    "## Daemon keep-up",
    "## Memory",
    "## Targets",
)


def bench_module(name: str) -> ModuleType:
    """Import a helper module of benchmarks/ the way bench.py does (its folder on sys.path)."""
    if str(BENCH_DIR) not in sys.path:
        sys.path.insert(0, str(BENCH_DIR))
    return importlib.import_module(name)


def table_after(text: str, heading: str) -> List[Dict[str, str]]:
    """The rows of the first markdown table after ``heading``, as dicts keyed by column header."""
    lines = text[text.index(heading):].splitlines()[1:]
    start = next(i for i, ln in enumerate(lines) if ln.startswith("|"))
    rows = []
    for ln in lines[start:]:
        if not ln.startswith("|"):
            break
        rows.append([c.strip() for c in ln.strip("|").split("|")])
    header, body = rows[0], rows[2:]
    return [dict(zip(header, r)) for r in body]


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory: pytest.TempPathFactory) -> Tuple[subprocess.CompletedProcess, Path]:
    out = tmp_path_factory.mktemp("bench") / "RESULTS.md"
    proc = subprocess.run(
        [sys.executable, str(BENCH_DIR / "bench.py"), "--quick", "--out", str(out)],
        cwd=REPO, capture_output=True, text=True, timeout=120, check=False,
    )
    return proc, out


def test_quick_run_exits_zero_and_prints_every_table(quick_run):
    proc, _ = quick_run
    assert proc.returncode == 0, proc.stderr
    for heading in HEADINGS:
        assert heading in proc.stdout, heading


def test_quick_run_figures_are_sane_and_the_pipeline_found_its_landmarks(quick_run):
    proc, _ = quick_run
    rows = table_after(proc.stdout, "## Per-frame time")
    full = {int(r["N"]): r for r in rows if r["contender"] == "full"}
    assert set(full) == {0, 1, 10}
    for n, row in full.items():
        assert 0.0 < float(row["median ms"]) < 1000.0
        assert float(row["median ms"]) <= float(row["p90 ms"])
        assert row["found per frame"].startswith(f"{n} of {n} landmarks ✓")
    worst_range_pct = float(full[1]["worst range / bearing error"].split("%")[0])
    assert worst_range_pct < 5.0  # the readings are right, not just present
    aruco = [r for r in rows if r["contender"] == "aruco"]
    if aruco:  # OpenCV without cv2.aruco skips this contender
        assert all("✓" in r["found per frame"] for r in aruco)


def test_quick_run_daemon_processed_and_published_every_frame(quick_run):
    proc, _ = quick_run
    (row,) = table_after(proc.stdout, "## Daemon keep-up")
    done, expected = (int(x) for x in row["frames processed"].split("/"))
    assert expected == 90 and 0 < done <= expected  # 1 s at 90 fps; drops depend on the machine
    assert int(row["datagrams received"]) == done
    assert int(row["bad"]) == 0


def test_quick_run_judges_every_target(quick_run):
    proc, _ = quick_run
    rows = table_after(proc.stdout, "## Targets")
    assert len(rows) == 6
    # INVALID means a contender missed landmarks it should have found: its time would mean nothing
    assert all(r["result"].split()[0] in ("PASS", "MISS", "n/a") for r in rows), rows


def test_out_file_has_the_machine_header_the_command_and_the_tables(quick_run):
    proc, out = quick_run
    text = out.read_text(encoding="utf-8")
    assert text.startswith("# rangebearing speed benchmark")
    assert f"Command: `python benchmarks/bench.py --quick --out {out}`" in text
    for item in ("CPU:", "OS:", "Python ", "numpy ", "OpenCV "):
        assert item in text
    assert proc.stdout.strip() in text


def test_repeats_below_one_is_a_usage_error():
    proc = subprocess.run(
        [sys.executable, str(BENCH_DIR / "bench.py"), "--repeats", "0"],
        cwd=REPO, capture_output=True, text=True, timeout=60, check=False,
    )
    assert proc.returncode == 2
    assert "--repeats must be at least 1" in proc.stderr


@pytest.mark.parametrize(("w", "h"), [(320, 240), (640, 480), (1280, 720)])
def test_pi_camera_keeps_the_field_of_view_and_the_model_follows_the_focal_length(w, h):
    frames = bench_module("bench_frames")
    cam = frames.pi_camera(w, h)
    assert math.degrees(cam.hfov_rad) == pytest.approx(53.5)
    assert (cam.cx_px, cam.cy_px) == ((w - 1) / 2, (h - 1) / 2)
    cfg = frames.camera_config(Config(), cam)
    assert cfg.camera == cam
    assert cfg.model.k_px_m == pytest.approx(cam.fy_px * 0.055)


@pytest.mark.parametrize("n", [1, 5, 10])
def test_markers_sit_in_free_space_apart_from_landmarks_and_each_other(n):
    frames = bench_module("bench_frames")
    cam = frames.pi_camera(640, 480)
    scenes = [Scene(camera=cam, landmarks=frames.poses(n, cam, 2 * math.pi * k / 8), wall_distance_m=2.0)
              for k in range(8)]
    markers, scale = frames.place_markers(scenes, [100.0] * n)
    assert len(markers) == n and 0.5 <= scale <= 1.0
    squares = [(x, y, x + s, y + s) for x, y, s, _ in markers]
    for x0, y0, x1, y1 in squares:
        assert x0 >= 0 and y0 >= 0 and x1 <= 640 and y1 <= 480
        for scene in scenes:
            for lm in scene.landmarks:
                u0, v0, u1, v1 = landmark_bbox_px(scene, lm, with_robot=True)
                assert x1 <= u0 or u1 <= x0 or y1 <= v0 or v1 <= y0  # no overlap with any landmark or robot
    for i, a in enumerate(squares):
        for b in squares[i + 1:]:
            assert a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1]
