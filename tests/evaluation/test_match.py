import math

import pytest

from rangebearing.core.types import Landmark
from rangebearing.evaluation.match import accuracy, format_report, match_frame
from rangebearing.evaluation.truth import TruthRow


def lm(range_m, bearing_deg):
    b = math.radians(bearing_deg)
    return Landmark(range_m, b, range_m, 0.0, 50.0, (0.0, 0.0), (0.0, 50.0), 20.0, (0, 0, 20, 60), True)


def test_matching_by_bearing_counts_misses_and_false_landmarks():
    truths = [TruthRow("f", 0.5, math.radians(10)), TruthRow("f", 1.0, math.radians(-20))]
    found = [lm(1.01, -20.1), lm(0.7, 25.0)]  # one right, one far from any truth
    matches, false = match_frame("f", found, truths)
    assert matches[0].found is None and math.isnan(matches[0].range_err_pct)
    assert matches[1].found is found[0]
    assert matches[1].range_err_pct == pytest.approx(1.0)
    assert matches[1].bearing_err_deg == pytest.approx(0.1)
    assert false == [found[1]]


def test_report_by_hand():
    frames = [
        ("a", [lm(0.505, 0.0)], [TruthRow("a", 0.5, 0.0)]),  # 1 % range error
        ("b", [], [TruthRow("b", 0.8, 0.2)]),  # missed
        ("c", [lm(0.3, 5.0)], []),  # false
    ]
    report, _ = accuracy(frames)
    assert (report.frames, report.truths, report.detected, report.false_landmarks) == (3, 2, 1, 1)
    assert report.detection_rate == 0.5
    assert report.range_err_pct_mean == pytest.approx(1.0)
    assert "detected          1 (50.0 %)" in format_report(report)


def test_report_says_so_when_the_truth_has_no_visible_share():
    report, _ = accuracy([("a", [lm(0.505, 0.0)], [TruthRow("a", 0.5, 0.0)])])
    assert math.isnan(report.visible_err_mean)
    line = [ln for ln in format_report(report).splitlines() if ln.startswith("visible error")]
    assert line == ["visible error     - (the truth gives no visible share)"]
