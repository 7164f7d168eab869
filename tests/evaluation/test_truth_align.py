"""Truth that names frames the way people do is matched; truth that matches nothing is refused (item 15)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from rangebearing.cli.main import main
from rangebearing.core.types import Landmark
from rangebearing.errors import TruthError
from rangebearing.evaluation.match import match_frame
from rangebearing.evaluation.truth import TruthRow, align_truth, read_truth

CLIP = Path(__file__).resolve().parents[2] / "samples" / "clip"
FRAMES = ["000000.jpg", "000001.jpg", "000002.jpg"]


def _truth(tmp_path: Path, text: str, bom: bool = False) -> Path:
    f = tmp_path / "truth.csv"
    f.write_bytes(("\ufeff" if bom else "").encode() + text.encode())
    return f


@pytest.mark.parametrize("name", ["samples/clip/000001.jpg", "000001.JPG", "000001", "1", "./000001.jpg"])
def test_frame_names_match_by_file_name_case_stem_or_number(tmp_path: Path, name: str) -> None:
    truth = read_truth(_truth(tmp_path, f"frame,range_m,bearing_rad\n{name},0.5,0.1\n"))
    assert list(align_truth(truth, FRAMES)) == ["000001.jpg"]


def test_truth_that_names_no_frame_is_refused_with_the_names(tmp_path: Path) -> None:
    truth = read_truth(_truth(tmp_path, "frame,range_m,bearing_rad\nclip.mp4,0.5,0.1\n000002.png,0.5,0.1\n"
                                        "img_7.jpg,0.4,0.0\n"))
    with pytest.raises(TruthError, match=r"2 of 3 truth frame\(s\) match no frame: 'clip.mp4', 'img_7.jpg'"):
        align_truth(truth, FRAMES)  # 000002.png matches 000002.jpg by its stem


def test_a_video_s_frames_are_its_0_based_indices(tmp_path: Path) -> None:
    truth = read_truth(_truth(tmp_path, "frame,range_m,bearing_rad\n0,0.5,0.1\n000002,0.6,0.0\n"))
    assert sorted(align_truth(truth, ["0", "1", "2"])) == ["0", "2"]
    with pytest.raises(TruthError, match="0-based index"):
        align_truth(truth, ["0", "1"])


def test_a_byte_order_mark_in_the_header_works(tmp_path: Path) -> None:
    truth = read_truth(_truth(tmp_path, "frame,range_m,bearing_rad\r\n000000.jpg,0.5,0.1\r\n", bom=True))
    assert truth["000000.jpg"][0].range_m == 0.5


def test_every_bad_row_is_reported(tmp_path: Path) -> None:
    f = _truth(tmp_path, "frame,range_m,bearing_rad\na.png,0,0.1\nb.png,0.5,4.0\nc.png,x,0.1\nd.png,0.5,0.1\n"
                         "e.png,-1,-3.5\n")
    with pytest.raises(TruthError) as info:
        read_truth(f)
    text = str(info.value)
    assert "4 bad rows" in text
    for line in (":2: range_m 0.0 is zero: must be > 0", ":3: bearing_rad 4.0 is outside ±π", ":4: range_m 'x'", ":6:"):
        assert line in text, line


def _lm(range_m: float, bearing_rad: float) -> Landmark:
    return Landmark(range_m, bearing_rad, range_m, 0.0, 50.0, (1.0, 1.0), (1.0, 2.0), 5.0, (0, 0, 1, 1), True)


def test_detections_are_matched_by_bearing_and_range() -> None:
    near, far = TruthRow("f", 0.5, 0.10), TruthRow("f", 1.0, 0.10)  # one behind the other
    found = [_lm(1.01, 0.101), _lm(0.51, 0.102)]  # the far one is closer in bearing to both
    matches, false = match_frame("f", found, [near, far])
    assert not false
    assert [m.found.range_m for m in matches if m.found] == [0.51, 1.01]
    assert math.isfinite(matches[0].range_err_pct) and abs(matches[0].range_err_pct) < 3


def test_replay_refuses_truth_for_other_frames(tmp_path: Path, capsys: Any) -> None:
    f = _truth(tmp_path, "frame,range_m,bearing_rad\nother/999999.jpg,0.5,0.1\n")
    assert main(["replay", str(CLIP), "--truth", str(f), "-q"]) != 0
    err = capsys.readouterr().err
    assert "match no frame" in err and "100.0 %" not in err
