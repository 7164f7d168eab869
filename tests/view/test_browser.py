"""The view page in a real browser (headless Chromium): frames show, the plot puts the bundled clip's
landmarks at the bearings the pipeline measures, a threshold slider changes detection, save writes the file."""

from __future__ import annotations

import csv
import math
import shutil
from pathlib import Path
from typing import Iterator, List, Tuple

import cv2
import numpy as np
import pytest

from rangebearing.config import load_config
from rangebearing.core.pipeline import Pipeline
from tests.view.browser import browser_context
from tests.view.processes import Served

REPO = Path(__file__).resolve().parents[2]
CLIP = REPO / "samples" / "clip"
SHOTS = Path("/tmp")


@pytest.fixture(scope="module")
def context() -> Iterator[object]:
    yield from browser_context()


@pytest.fixture(scope="module")
def view(context, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Tuple[str, Path]]:
    """``rangebearing view`` on the bundled clip (paced at 4 fps, looping) with a copy of the default config."""
    cfg_path = tmp_path_factory.mktemp("view") / "rangebearing.yaml"
    shutil.copy(REPO / "config" / "rangebearing.yaml", cfg_path)
    served = Served(["view", "--config", str(cfg_path), "--source", str(CLIP), "--loop", "--fps", "4", "--port", "0"])
    try:
        yield served.url, cfg_path  # type: ignore[misc]
    finally:
        assert served.stop() == 0, "".join(served.log)


@pytest.fixture
def page(context, view):
    pg = context.new_page()
    errors: List[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.goto(view[0])
    pg.wait_for_selector("#readings tbody tr", timeout=15000)
    yield pg
    pg.close()
    assert errors == [], f"JavaScript errors on the page: {errors}"


def set_slider(pg, selector: str, value: int) -> None:
    pg.fill(selector, str(value))


def test_stream_shows_frames(page) -> None:
    size = page.evaluate("(i => [i.naturalWidth, i.naturalHeight])(document.getElementById('stream'))")
    assert size == [640, 480]
    seq = int(page.get_attribute("body", "data-seq"))
    shot = page.locator("#stream").screenshot()
    page.wait_for_function(f"+document.body.dataset.seq > {seq + 1}", timeout=10000)
    assert page.locator("#stream").screenshot() != shot  # new frames arrive
    page.screenshot(path=str(SHOTS / "view-page.png"), full_page=True)


def truth_bearings(name: str) -> List[float]:
    with open(CLIP / "truth.csv") as f:
        return sorted(float(r["bearing_rad"]) for r in csv.DictReader(f) if r["frame"] == name)


def test_plot_puts_landmarks_at_the_measured_bearings(page) -> None:
    plotted = page.evaluate(
        """() => { const c = document.getElementById('plot').dataset;
        return { ox: +c.originX, oy: +c.originY, rows: [...document.querySelectorAll('#readings tbody tr')]
          .map(r => ({ x: +r.dataset.xPx, y: +r.dataset.yPx, bearing: +r.dataset.bearingRad,
                       range: +r.dataset.rangeM, frame: r.dataset.frame, track: +r.dataset.trackId })) }; }"""
    )
    rows = sorted(plotted["rows"], key=lambda r: r["bearing"])
    assert len(rows) == 2
    frame = rows[0]["frame"]
    pipe = Pipeline(load_config(REPO / "config" / "rangebearing.yaml").pipeline, track=False)
    measured = pipe.process(cv2.imread(str(CLIP / frame))).landmarks
    for row, lm, truth in zip(rows, sorted(measured, key=lambda m: m.bearing_rad), truth_bearings(frame)):
        # the bearing the plot shows: the angle of the dot from straight up, positive to the left
        shown = math.atan2(plotted["ox"] - row["x"], plotted["oy"] - row["y"])
        assert shown == pytest.approx(row["bearing"], abs=1e-6)
        assert shown == pytest.approx(lm.bearing_rad, abs=math.radians(0.3))
        assert shown == pytest.approx(truth, abs=math.radians(0.5))
        assert row["range"] == pytest.approx(lm.range_m, rel=0.02)
    assert sorted(r["track"] for r in rows) == sorted({r["track"] for r in rows}) and min(r["track"] for r in rows) >= 0
    left, right = rows[1], rows[0]
    assert left["bearing"] > 0 > right["bearing"] and left["x"] < plotted["ox"] < right["x"]  # left is left


def overlay_pixels(pg) -> int:
    """Pixels of the stream drawn in the overlay's green (the clip itself has none)."""
    img = cv2.imdecode(np.frombuffer(pg.locator("#stream").screenshot(), np.uint8), cv2.IMREAD_COLOR).astype(int)
    b, g, r = img[:, :, 0], img[:, :, 1], img[:, :, 2]
    return int(((g - r > 80) & (g - b > 80)).sum())


def wait_frames(pg, n: int) -> None:
    seq = int(pg.get_attribute("body", "data-seq"))
    pg.wait_for_function(f"+document.body.dataset.seq >= {seq + n}", timeout=10000)


def test_raising_s_min_hides_the_landmarks(page) -> None:
    assert overlay_pixels(page) > 10  # boxes and labels drawn around both landmarks
    set_slider(page, "#s_min", 255)
    page.wait_for_function("document.body.dataset.sMin === '255'", timeout=10000)
    page.wait_for_function("document.querySelectorAll('#readings tbody tr').length === 0", timeout=10000)
    assert "s ≥ 255" in page.inner_text("#message")
    wait_frames(page, 2)
    assert overlay_pixels(page) == 0  # nothing detected, nothing drawn
    page.screenshot(path=str(SHOTS / "view-s-min-255.png"))
    set_slider(page, "#s_min", 90)
    page.wait_for_function("document.querySelectorAll('#readings tbody tr').length === 2", timeout=10000)


def test_masks_on_demand(page) -> None:
    assert page.evaluate("document.getElementById('masks').hidden")
    page.check("#show-masks")
    page.wait_for_function("document.getElementById('masks').naturalWidth === 320", timeout=10000)
    page.screenshot(path=str(SHOTS / "view-masks.png"), full_page=True)


def test_save_writes_the_config_atomically_with_a_backup(page, view) -> None:
    cfg_path = view[1]
    old = cfg_path.read_bytes()
    set_slider(page, "#v_min", 40)
    page.wait_for_function("document.getElementById('message').textContent.includes('v ≥ 40')", timeout=10000)
    page.click("#save")
    page.wait_for_function("document.getElementById('message').textContent.includes('saved to')", timeout=10000)
    assert load_config(cfg_path).detection.v_min == 40
    assert (cfg_path.parent / "rangebearing.yaml.bak").read_bytes() == old
    assert "# minimum value/brightness" in cfg_path.read_text()  # comments kept
    set_slider(page, "#v_min", 25)
