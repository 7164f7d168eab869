"""The speed benchmark runs end to end (``--quick``) and its helpers place frames honestly.

No timing is asserted here: the speed targets live in the benchmark's own
printed figures (benchmarks/RESULTS.md), never in unit tests.
"""

from __future__ import annotations

import importlib
import importlib.util
import math
import subprocess
import sys
from pathlib import Path
from types import ModuleType
from typing import Dict, List, Tuple

import numpy as np
import pytest

from rangebearing import Config
from rangebearing.synth import Scene, landmark_bbox_px

REPO = Path(__file__).resolve().parents[1]
BENCH_DIR = REPO / "benchmarks"
HEADINGS = (
    "## Per-frame CPU time, cold and warm",
    "## Tracking (consecutive frames)",
    "## Ratios (same run",
    "## Landmark count and pixel count (full, cold)",
    "## Stage breakdown",
    "## Daemon (`rangebearing run` subprocess, paced recording)",
    "## Memory",
    "## Targets",
)
HAS_APRILTAG = importlib.util.find_spec("pupil_apriltags") is not None


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
        cwd=REPO, capture_output=True, text=True, timeout=900, check=False,  # ~30 s quiet; a loaded machine
    )
    return proc, out


def test_quick_run_exits_zero_and_prints_every_table(quick_run):
    proc, _ = quick_run
    assert proc.returncode == 0, proc.stderr
    for heading in HEADINGS:
        assert heading in proc.stdout, heading


def test_quick_run_figures_are_sane_and_every_contender_found_what_it_should(quick_run):
    proc, _ = quick_run
    rows = table_after(proc.stdout, "## Per-frame CPU time")
    full = {r["scene"]: r for r in rows if r["contender"] == "full"}
    assert {"N=0", "N=1", "N=10", "clutter", "sample"} <= set(full)
    for n in (0, 1, 10):
        row = full[f"N={n}"]
        assert 0.0 < float(row["cold CPU ms"]) < 1000.0 and 0.0 < float(row["warm CPU ms"]) < 1000.0
        assert float(row["cold CPU ms"]) <= float(row["cold p90"])
        assert row["found per frame"].startswith(f"{n} of {n} landmarks ✓")
    assert full["clutter"]["found per frame"].endswith("✓") and full["sample"]["found per frame"].endswith("✓")
    worst_range_pct = float(full["N=1"]["worst range / bearing error"].split("%")[0])
    assert worst_range_pct < 5.0  # the readings are right, not just present
    markers = [r for r in rows if r["contender"] in ("aruco", "apriltag d2", "apriltag d1")]
    assert all("✓" in r["found per frame"] for r in markers), markers
    names = {r["contender"] for r in markers}
    if HAS_APRILTAG:
        assert {"apriltag d2", "apriltag d1"} <= names
        ten = [r for r in markers if r["scene"] == "N=10" and r["contender"] == "apriltag d2"]
        assert ten and ten[0]["found per frame"].startswith("10 of 10 markers")
    track = {r["scene"]: r for r in table_after(proc.stdout, "## Tracking")}
    assert "clutter" not in track  # independent frames are not tracked
    for scene in ("N=1", "N=10", "sample"):
        assert track[scene]["found per frame"].endswith("✓"), track[scene]
        assert float(track[scene]["tracked frames cold ms"]) > 0.0


def test_quick_run_daemon_subprocess_published_paced_frames(quick_run):
    proc, _ = quick_run
    rows = table_after(proc.stdout, "## Daemon")
    assert [r["fps asked"] for r in rows] == ["30", "90"]
    for row in rows:
        sent, due = (int(x) for x in row["datagrams / frames due"].split("/"))
        # a 1 s window, as long as the harness's sleep really took (under load it overshoots by tens of ms)
        assert abs(due - int(row["fps asked"])) <= max(2, 0.1 * due)
        # published, never more than due (how many of them is throughput: a starved machine sends fewer)
        assert 0 < sent <= due + 2
        assert 0.0 < float(row["start-up s (to 1st datagram)"]) < 30.0
        assert 0.0 < float(row["CPU % of a core"]) < 100.0
        rss, peak = (float(x) for x in row["RSS / peak MiB"].split("/"))
        assert 10.0 < rss <= peak
        assert row["exit"] == "0"  # SIGTERM ends it cleanly


def test_quick_run_judges_every_target(quick_run):
    proc, _ = quick_run
    rows = table_after(proc.stdout, "## Targets")
    judged = {r["target"].split(" (")[0] for r in rows}
    assert len(rows) >= 9, rows
    assert any("apriltag d2" in t for t in judged) and any("daemon at 90 fps" in t for t in judged)
    # INVALID means a contender missed what it should have found: its time would mean nothing
    assert all(r["result"].split()[0] in ("PASS", "MISS", "n/a") for r in rows), rows
    if HAS_APRILTAG:
        assert all(r["result"] != "n/a" for r in rows), rows


def test_out_file_has_the_machine_header_the_command_and_the_tables(quick_run):
    proc, out = quick_run
    text = out.read_text(encoding="utf-8")
    assert text.startswith("# rangebearing speed benchmark")
    assert f"Command: `python benchmarks/bench.py --quick --out {out}`" in text
    for item in ("CPU:", "OS:", "Python ", "numpy ", "OpenCV "):
        assert item in text
    assert proc.stdout.strip() in text


@pytest.mark.parametrize("flag", ["--repeats", "--passes"])
def test_repeats_or_passes_below_one_is_a_usage_error(flag):
    proc = subprocess.run(
        [sys.executable, str(BENCH_DIR / "bench.py"), flag, "0"],
        cwd=REPO, capture_output=True, text=True, timeout=60, check=False,
    )
    assert proc.returncode == 2
    assert f"{flag} must be at least 1" in proc.stderr


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
    markers, scale = frames.place_markers(scenes, [100.0] * n, ("aruco", "apriltag"))
    assert len(markers) == 2 * n and 0.3 <= scale <= 1.0
    assert sorted(m[3] for m in markers if m[4] == "apriltag") == list(range(n))
    squares = [(x, y, x + s, y + s) for x, y, s, *_ in markers]
    for x0, y0, x1, y1 in squares:
        assert x0 >= 0 and y0 >= 0 and x1 <= 640 and y1 <= 480
        for scene in scenes:
            for lm in scene.landmarks:
                u0, v0, u1, v1 = landmark_bbox_px(scene, lm, with_robot=True)
                assert x1 <= u0 or u1 <= x0 or y1 <= v0 or v1 <= y0  # no overlap with any landmark or robot
    for i, a in enumerate(squares):
        for b in squares[i + 1:]:
            assert a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1]


def test_cold_run_interleaves_shuffled_contenders_with_a_sleep_before_every_call():
    timing = bench_module("bench_timing")
    calls, sleeps = [], []

    def contender(name):
        return timing.Contender(name, lambda frame, n=name: calls.append((n, int(frame[0, 0, 0]))), lambda i: 0)

    cs = [contender(n) for n in "abcd"]
    frames = [np.full((2, 2, 3), i, np.uint8) for i in range(6)]
    timing.run_cold(cs, frames, passes=2, gap_s=(0.011, 0.033), seed=3, sleep=sleeps.append)
    assert len(calls) == len(sleeps) == 4 * 6 * 2
    assert all(0.011 <= s <= 0.033 for s in sleeps)
    blocks = [calls[i:i + 4] for i in range(0, len(calls), 4)]
    for k, block in enumerate(blocks):  # frame by frame: every contender once per frame, in frame order
        assert sorted(n for n, _ in block) == list("abcd") and {f for _, f in block} == {k % 6}
    assert len({tuple(n for n, _ in b) for b in blocks}) > 1  # the order is shuffled
    assert all(len(c.cold_cpu_ns) == 12 and min(c.cold_cpu_ns) >= 0 for c in cs)


@pytest.mark.skipif(not HAS_APRILTAG, reason="pupil-apriltags (the bench extra) is not installed")
def test_painted_tag_bitmaps_are_the_apriltag_library_codes():
    tags = bench_module("bench_apriltag")
    grey = np.full((200, 400), 200, np.uint8)
    for k, img in enumerate(tags.tag_images([(3, 64), (17, 64), (250, 64)])):
        grey[40:104, 20 + 120 * k: 84 + 120 * k] = img
    detect = tags.make_detector(2.0)
    assert sorted(detect(np.dstack([grey] * 3))) == [3, 17, 250]


def test_a_reading_of_a_partly_hidden_landmark_is_neither_wanted_nor_false():
    timing, frames_mod = bench_module("bench_timing"), bench_module("bench_frames")
    from rangebearing import FrameResult, Landmark
    from rangebearing.synth.scene import LandmarkPose

    near, hidden, far = LandmarkPose(0.5, 0.1), LandmarkPose(0.8, 0.1), LandmarkPose(1.5, -0.3)

    def reading(r: float, b: float) -> Landmark:
        return Landmark(r, b, r, 0.0, 60.0, (0.0, 0.0), (0.0, 0.0), 10.0, (0, 0, 1, 1), True)

    sc = frames_mod.ScenarioFrames(640, 480, 2, Config(), [], [(near, far)] * 3, [], 1.0, "crowd",
                                   seen=[(near, hidden, far)] * 3)
    outs = [FrameResult((reading(0.51, 0.1), reading(0.79, 0.1), reading(1.5, -0.3))),  # the hidden one too: right
            FrameResult((reading(0.5, 0.1),)),  # the far one missed
            FrameResult((reading(0.5, 0.1), reading(1.5, -0.3), reading(0.3, 0.4)))]  # one false
    assert [(w, f, len(got)) for w, f, got in (timing.judged(o, sc, i) for i, o in enumerate(outs))] == [
        (2, 0, 2), (2, 0, 1), (2, 1, 2)]
    c = timing.Contender("full", lambda f: None, lambda i: 2)
    c.outputs = list(enumerate(outs))
    text, ok = timing._found(c, sc)
    assert not ok and text == "1–2 of 2 landmarks, 1 false ✗"
    assert timing._errors(c, sc) == "2.0 % / 0.00°"  # the worst findable one, matched, not zipped by bearing
