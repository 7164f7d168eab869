"""``calibrate --guided`` end to end: the fake Pi camera shows where a scripted operator put the landmark."""

import importlib.util
import io
import math

import pytest
import yaml

from rangebearing.cli.main import main
from rangebearing.config import load_config
from rangebearing.core.types import CameraIntrinsics
from rangebearing.evaluation.truth import read_truth
from rangebearing.synth import LandmarkPose, Scene, render

CAM = CameraIntrinsics().scaled(320, 240)
PLAN = [(0.25, 0.0), (0.35, 15.0), (0.5, 0.0), (0.6, -15.0), (0.8, 8.0), (1.0, 0.0), (0.7, 0.0)]


class Operator(io.StringIO):
    """Stdin that, before each answer, moves the landmark as told: ``(station index or None, answer)``."""

    def __init__(self, script, world):
        super().__init__()
        self.script = list(script)
        self.frames = {}
        self.current = render(Scene(camera=CAM))[:, :, ::-1].copy()
        world.producer = lambda seq, h, w: self.current

    def readline(self, *args):
        if not self.script:
            return ""  # end of input: the operator walked away
        where, answer = self.script.pop(0)
        if where is not None and where not in self.frames:
            r, b = PLAN[where]
            scene = Scene(camera=CAM, landmarks=(LandmarkPose(r, math.radians(b)),))
            self.frames[where] = render(scene)[:, :, ::-1].copy()
        self.current = self.frames[where] if where is not None else render(Scene(camera=CAM))[:, :, ::-1].copy()
        return answer + "\n"


@pytest.fixture
def setup(tmp_path, fake_picamera2):
    plan = tmp_path / "plan.csv"
    plan.write_text("range_m,bearing_deg\n" + "".join(f"{r},{b}\n" for r, b in PLAN))
    cfg = tmp_path / "robot.yaml"
    cfg.write_text(yaml.safe_dump({"source": {"kind": "picamera2", "width_px": 320, "height_px": 240}}))
    return plan, cfg, fake_picamera2.WORLD


def test_guided_session_records_checks_fits_and_can_be_redone(setup, tmp_path, capsys, monkeypatch):
    plan, cfg, world = setup
    script = [(0, ""), (None, ""), (1, ""), (2, "s"), (3, ""), (4, ""), (5, ""), (6, "")]
    monkeypatch.setattr("sys.stdin", Operator(script, world))
    out = tmp_path / "calibrated.yaml"
    args = ["calibrate", "--guided", "--plan", str(plan), "--config", str(cfg), "--out", str(out),
            "--frames-per-station", "3", "--strict"]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "place a landmark 0.25 m straight ahead" in text
    assert "place a landmark 0.35 m 15° to the left (0.338 m ahead, 0.091 m left)" in text
    assert "s02 not recorded: landmark found in 0 of 3 frames" in text  # the empty view was refused, then redone
    assert "6 of 7 stations recorded, 18 frames" in text
    assert "focal length agrees" in text

    record = tmp_path / "calibrated-recording"
    truth = read_truth(record / "truth.csv")
    if importlib.util.find_spec("matplotlib") is not None:  # the plot is drawn when matplotlib is there
        assert (record / "fit.png").stat().st_size > 1000
    assert len(truth) == 18 and not any(name.startswith("s03") for name in truth)
    assert (record / "plan.csv").read_text().startswith("name,range_m,bearing_deg\ns01,0.2500,0.000")
    fitted = load_config(out)
    assert fitted.source.kind == "picamera2"
    assert fitted.model.envelope_range_m == (0.25, 1.0)
    assert "range error mean 0." in text  # under 1 %

    # the recording is enough to redo the fit without the robot
    again = tmp_path / "again.yaml"
    assert main(["calibrate", str(record), "--truth", str(record / "truth.csv"), "--config", str(cfg),
                 "--out", str(again)]) == 0
    assert load_config(again).model == fitted.model


def test_guided_session_stopped_early_keeps_a_consistent_recording(setup, tmp_path, capsys, monkeypatch):
    plan, cfg, world = setup
    monkeypatch.setattr("sys.stdin", Operator([(0, ""), (1, ""), (2, "q")], world))
    out = tmp_path / "c.yaml"
    args = ["calibrate", "--guided", "--plan", str(plan), "--config", str(cfg), "--out", str(out),
            "--frames-per-station", "2"]
    assert main(args) == 1  # two stations: too few to fit
    captured = capsys.readouterr()
    assert "stopped at s03: 2 station(s) recorded" in captured.out
    assert "2 station(s) recorded, at least 4 are needed" in captured.err
    assert not out.exists()
    assert len(read_truth(tmp_path / "c-recording" / "truth.csv")) == 4
