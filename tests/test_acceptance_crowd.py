"""Issue 8's sets, measured as a user would: `rangebearing calibrate` on a 0.2–1.4 m set, then the
pipeline on held-out seeds of the occlusion, touching, crowd and far presets against their truth.

The sets are small (40 frames) to keep the suite fast; the README table's figures come from the
bigger runs its commands give. The bounds here are what the structure search holds today, so a
regression fails; where they are looser than the issue's targets the README says so.
"""

from __future__ import annotations

import cv2
import pytest

from rangebearing import Pipeline, load_config
from rangebearing.cli.main import main
from rangebearing.evaluation.match import accuracy
from rangebearing.evaluation.truth import write_truth
from rangebearing.synth import generate

# preset, frames, seed, min share of findable found, max false per frame, max p95 range error %,
# max p95 bearing error °. (The means are not bounded here: a rare gross error, e.g. a robot's red
# flag in front of its own white body read as the band, still moves them; see docs/detection.md.)
SETS = [
    ("occlusion", 40, 6201, 0.90, 0.1, 3.0, 0.3),
    ("crowd", 30, 6203, 0.85, 0.2, 4.0, 1.2),
    ("far", 40, 6204, 0.85, 0.05, 3.5, 0.3),
    ("touching", 40, 6202, 0.70, 0.15, 3.5, 1.0),
]


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    """A config written by `rangebearing calibrate` from wide-preset frames with ranges 0.2–1.4 m."""
    root = tmp_path_factory.mktemp("cal14")
    frames, rows = root / "frames", []
    frames.mkdir()
    for name, img, truth in generate(90, 4343, "wide", fmt="png"):
        if truth and all(0.2 <= t.range_m <= 1.4 for t in truth):
            cv2.imwrite(str(frames / name), img)
            rows.extend(truth)
    write_truth(frames / "truth.csv", rows)
    out = root / "calibrated.yaml"
    assert main(["calibrate", str(frames), "--truth", str(frames / "truth.csv"), "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def reports(calibrated):
    pipe = Pipeline(load_config(calibrated).pipeline, track=False)
    out = {}
    for preset, n, seed, *_ in SETS:
        out[preset] = accuracy(
            (name, pipe.process(img).landmarks, rows) for name, img, rows in generate(n, seed, preset)
        )[0]
    return out


@pytest.mark.parametrize("preset, n, seed, min_found, max_false, max_p95, max_bearing", SETS)
def test_crowded_sets_keep_their_bounds(reports, preset, n, seed, min_found, max_false, max_p95, max_bearing):
    rep = reports[preset]
    assert rep.findable > 0
    assert rep.findable_rate >= min_found
    assert rep.false_on_empty == 0  # nothing is ever seen where there is no landmark
    assert rep.false_landmarks <= max_false * rep.frames
    assert rep.range_err_pct_p95 <= max_p95
    assert rep.bearing_err_deg_p95 <= max_bearing


@pytest.mark.parametrize("preset", ["occlusion", "far"])
def test_sigma_is_calibrated_on_the_uncrowded_sets(reports, preset):
    rep = reports[preset]
    assert 0.85 <= rep.range_cover <= 1.0
    assert 0.8 <= rep.bearing_cover <= 1.0
