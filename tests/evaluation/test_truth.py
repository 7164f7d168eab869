"""Ground-truth CSV: round trips and clear errors."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rangebearing.errors import RangeBearingError, TruthError
from rangebearing.evaluation.truth import TruthRow, read_truth, write_truth


def test_round_trip_groups_rows_by_frame_in_order(tmp_path):
    rows = [TruthRow("000000.png", 0.5, 0.1), TruthRow("000000.png", 1.25, -0.3),
            TruthRow("000002.png", 0.333333333, math.radians(-12.5))]
    path = tmp_path / "truth.csv"
    write_truth(path, rows)
    assert path.read_text().splitlines()[:2] == ["frame,range_m,bearing_rad",
                                                  "000000.png,0.500000,0.100000"]
    back = read_truth(path)
    assert list(back) == ["000000.png", "000002.png"]  # no rows: no landmark in 000001
    assert back["000000.png"] == rows[:2]
    (row,) = back["000002.png"]
    assert row.range_m == pytest.approx(0.333333, abs=1e-9)
    assert row.bearing_rad == pytest.approx(math.radians(-12.5), abs=5e-7)


def test_video_frames_are_indices_as_strings(tmp_path):
    path = tmp_path / "t.csv"
    write_truth(path, [TruthRow("0", 0.4, 0.0), TruthRow("17", 0.6, 0.2)])
    assert set(read_truth(path)) == {"0", "17"}


def test_empty_truth_is_a_header_only(tmp_path):
    path = tmp_path / "t.csv"
    write_truth(path, [])
    assert path.read_text() == "frame,range_m,bearing_rad\n"
    assert read_truth(path) == {}


def test_extra_columns_and_other_order_are_fine(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("note,bearing_rad,frame,range_m\nhand,-0.25,a.png,0.75\n\n,0.1,b.png,1\n")
    assert read_truth(path) == {"a.png": [TruthRow("a.png", 0.75, -0.25)],
                                "b.png": [TruthRow("b.png", 1.0, 0.1)]}


@pytest.mark.parametrize("text, where, words", [
    ("frame,range_m\na.png,0.5\n", ":1:", "missing column(s) bearing_rad"),
    ("", ":1:", "empty file"),
    ("frame,range_m,bearing_rad\na.png,0.5,0.1\nb.png,half,0.1\n", ":3:", "range_m 'half'"),
    ("frame,range_m,bearing_rad\na.png,0.5,\n", ":2:", "bearing_rad '' is not a number"),
    ("frame,range_m,bearing_rad\na.png,0.5,nan\n", ":2:", "not finite"),
    ("frame,range_m,bearing_rad\na.png,-0.5,0.1\n", ":2:", "negative"),
    ("frame,range_m,bearing_rad\n,0.5,0.1\n", ":2:", "empty frame"),
    ("frame,range_m,bearing_rad\na.png,0.5\n", ":2:", "too few fields"),
])
def test_malformed_files_name_file_line_and_reason(tmp_path, text, where, words):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(TruthError) as exc:
        read_truth(path)
    message = str(exc.value)
    assert message.startswith(str(path) + where)
    assert words in message


def test_missing_file_is_a_truth_error(tmp_path):
    with pytest.raises(TruthError, match="cannot read"):
        read_truth(tmp_path / "nope.csv")


def test_truth_error_is_in_the_tree():
    assert issubclass(TruthError, RangeBearingError) and issubclass(TruthError, ValueError)


finite = st.floats(-1e3, 1e3, allow_nan=False)


@settings(max_examples=50)
@given(st.lists(st.tuples(st.integers(0, 999), st.floats(1e-3, 100), st.floats(-3.14, 3.14)), max_size=20))
def test_round_trip_to_a_micro_unit(tmp_path_factory, items):
    path = tmp_path_factory.mktemp("t") / "truth.csv"
    # one landmark per place as read back (no doubles): keyed by the written text's value, so -0.000000 is 0.000000
    written = {(i, float(f"{r:.6f}"), float(f"{b:.6f}")): (i, r, b) for i, r, b in items}
    rows = [TruthRow(f"{i:06d}.png", r, b) for i, r, b in written.values()]
    write_truth(path, rows)
    back = [row for frame_rows in read_truth(path).values() for row in frame_rows]
    assert sorted(r.frame for r in back) == sorted(r.frame for r in rows)
    for frame in {r.frame for r in rows}:
        want = [r for r in rows if r.frame == frame]
        got = [r for r in back if r.frame == frame]
        for a, b in zip(want, got):
            assert b.range_m == pytest.approx(a.range_m, abs=5.1e-7)
            assert b.bearing_rad == pytest.approx(a.bearing_rad, abs=5.1e-7)


@pytest.mark.parametrize("text, says", [
    ("frame,range_m,bearing_rad\na.png,0.4,0.1\nb.png,0.5,0\na.png,0.4,0.1\n",
     "truth.csv:4: the same landmark as line 2"),
    ("frame,range_m,bearing_rad,range_m\na.png,0.4,0.1,0.5\n", "column(s) range_m given twice"),
])
def test_a_duplicated_row_or_column_is_refused(tmp_path: Path, text: str, says: str) -> None:
    """A doubled row made the replay count its copy as missed; a doubled column kept the last value silently."""
    path = tmp_path / "truth.csv"
    path.write_text(text)
    with pytest.raises(TruthError, match=re.escape(says)):
        read_truth(path)


def test_rows_read_as_lists_keep_what_a_reader_by_name_accepted(tmp_path: Path) -> None:
    # padded numbers, exponents, blank lines, cells past the header, a frame name with spaces
    text = ("\nframe , range_m,bearing_rad\n a b.png , 1.5 ,+0.2\n\n"
            "a b.png,1e-1,-3.14159,extra,cells\n002.png,0.3,0.0\n")
    path = tmp_path / "t.csv"
    path.write_text(text)
    truth = read_truth(path)
    assert truth == {"a b.png": [TruthRow("a b.png", 1.5, 0.2), TruthRow("a b.png", 0.1, -3.14159)],
                     "002.png": [TruthRow("002.png", 0.3, 0.0)]}
    path.write_text("frame,range_m,bearing_rad\n001.png,inf,0\n001.png,1,nan\n001.png,0.5\n")
    with pytest.raises(TruthError) as bad:
        read_truth(path)
    assert [ln.strip() for ln in str(bad.value).splitlines()[1:]] == [
        f"{path}:2: range_m 'inf' is not finite", f"{path}:3: bearing_rad 'nan' is not finite",
        f"{path}:4: too few fields"]
