"""Progress bars on a terminal only, and interrupted runs that leave consistent files."""

import pytest

from rangebearing.cli import common
from rangebearing.cli.main import main
from rangebearing.evaluation.truth import read_truth
from rangebearing.synth.dataset import write_dataset


def test_progress_draws_a_tqdm_bar_only_when_asked(capsys):
    assert list(common.progress(range(7), 7, "work", enabled=True)) == list(range(7))
    err = capsys.readouterr().err
    assert "work" in err and "7/7" in err
    assert list(common.progress(range(7), 7, "work")) == list(range(7))  # stderr is not a terminal here
    assert capsys.readouterr().err == ""


def interrupt_after(n):
    def fake_progress(items, total=None, label="", enabled=None, unit="frame"):
        for i, item in enumerate(items):
            if i == n:
                raise KeyboardInterrupt
            yield item
    return fake_progress


def test_interrupted_dataset_keeps_truth_for_the_frames_written(tmp_path):
    with pytest.raises(KeyboardInterrupt):
        write_dataset(tmp_path, 6, seed=1, preset="multi", wrap=interrupt_after(3))
    frames = sorted(p.name for p in tmp_path.glob("*.png"))
    assert frames == ["000000.png", "000001.png", "000002.png"]
    assert not list(tmp_path.glob(".*"))  # no half-written frame left behind
    truth = read_truth(tmp_path / "truth.csv")
    assert set(truth) <= set(frames) and len(truth) >= 3  # multi: 2-4 landmarks in every frame


def test_synth_command_says_what_it_finished(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("rangebearing.cli.synth_cmd.progress", interrupt_after(2))
    assert main(["synth", "--out", str(tmp_path), "--frames", "5", "--seed", "0"]) == 130
    assert "interrupted after 2 of 5 frames" in capsys.readouterr().err
    assert len(list(tmp_path.glob("*.png"))) == 2 and (tmp_path / "truth.csv").exists()


def test_replay_interrupted_reports_the_frames_done(static_clip, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("rangebearing.cli.replay_cmd.progress", interrupt_after(4))
    out = tmp_path / "r.jsonl"
    assert main(["replay", str(static_clip), "--out", str(out), "-q"]) == 130
    assert "interrupted after 4 frames" in capsys.readouterr().err
    assert len(out.read_text().splitlines()) == 4
