"""``rangebearing intrinsics`` on rendered chessboard frames with a known camera."""

import cv2
import numpy as np
import pytest

from rangebearing.cli.main import main
from rangebearing.config import load_config
from rangebearing.core.types import CameraIntrinsics
from rangebearing.synth.chessboard import random_views

TRUE = CameraIntrinsics(640, 480, 600.0, 598.0, 318.0, 242.0, (-0.2, 0.05, 0.0, 0.0, 0.0))


@pytest.fixture(scope="module")
def frames(tmp_path_factory):
    d = tmp_path_factory.mktemp("board")
    for i, v in enumerate(random_views(TRUE, 9, 6, 0.025, 10, seed=7)):
        cv2.imwrite(str(d / f"{i:06d}.png"), v.image)
    cv2.imwrite(str(d / "000099.png"), np.full((480, 640, 3), 128, np.uint8))  # no board in it
    return d


def test_intrinsics_writes_a_complete_config_with_the_camera(frames, tmp_path, capsys):
    out = tmp_path / "cam.yaml"
    assert main(["intrinsics", str(frames), "--board", "9x6", "--square-mm", "25", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "found in 10 of 11 frames" in text and "reprojection error RMS" in text
    cam = load_config(out).camera
    assert cam.fx_px == pytest.approx(TRUE.fx_px, rel=0.005)
    assert cam.fy_px == pytest.approx(TRUE.fy_px, rel=0.005)
    assert cam.distortion[0] == pytest.approx(-0.2, abs=0.02)
    # overwriting keeps the old file as a backup
    assert main(["intrinsics", str(frames), "--board", "9x6", "--square-mm", "25", "--out", str(out), "-q"]) == 0
    assert (tmp_path / "cam.yaml.bak").exists()


def test_intrinsics_refuses_poor_coverage_with_the_reason(frames, tmp_path, capsys):
    few = tmp_path / "few"
    few.mkdir()
    for p in sorted(frames.glob("*.png"))[:3]:
        (few / p.name).write_bytes(p.read_bytes())
    out = tmp_path / "cam.yaml"
    assert main(["intrinsics", str(few), "--board", "9x6", "--square-mm", "25", "--out", str(out)]) == 1
    assert "too few views" in capsys.readouterr().err
    assert not out.exists()


def test_bad_board_argument_is_an_argparse_error(frames, capsys):
    with pytest.raises(SystemExit):
        main(["intrinsics", str(frames), "--board", "9by6", "--square-mm", "25", "--out", "x.yaml"])
    assert "COLSxROWS" in capsys.readouterr().err


def test_charuco_frames(tmp_path, capsys):
    from rangebearing.core.charuco import charuco_board
    from rangebearing.synth.charuco import random_charuco_views

    d = tmp_path / "charuco"
    d.mkdir()
    for i, v in enumerate(random_charuco_views(TRUE, charuco_board(10, 7, 0.025, 0.018, "4X4_50"), 10, seed=4)):
        cv2.imwrite(str(d / f"{i:06d}.png"), v.image)
    out = tmp_path / "cam.yaml"
    args = ["intrinsics", str(d), "--board", "10x7", "--square-mm", "25", "--out", str(out)]
    assert main([*args, "--charuco", "4X4_50"]) == 1
    assert "--marker-mm" in capsys.readouterr().err
    assert main([*args, "--charuco", "4X4_50", "--marker-mm", "18"]) == 0
    assert "board ChArUco 10x7" in capsys.readouterr().out
    cam = load_config(out).camera
    assert cam.fx_px == pytest.approx(TRUE.fx_px, rel=0.005)
    assert cam.fy_px == pytest.approx(TRUE.fy_px, rel=0.005)
