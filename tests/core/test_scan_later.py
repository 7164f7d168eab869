"""Pipeline.process_scan_later: a periodic full scan left for after the frame's readings, nothing else changed."""

from __future__ import annotations

import dataclasses

from tests.core.test_tracking import moving_sequence

from rangebearing import Pipeline, load_config


def _pipes(full_scan_every: int = 4):
    cfg = load_config(None)
    cfg = dataclasses.replace(cfg, detection=dataclasses.replace(cfg.detection, full_scan_every=full_scan_every,
                                                                  full_scan_interval_s=0.0))
    return Pipeline(cfg.pipeline, track=True), Pipeline(cfg.pipeline, track=True)


def test_only_the_periodic_scan_frames_read_otherwise_and_the_scan_leaves_the_state_process_would():
    now, later = _pipes()
    deferred = 0
    for i, img in enumerate(moving_sequence(14)):
        t_s = i / 30
        want = now.process(img, t_s=t_s)
        got, finish = later.process_scan_later(img, t_s=t_s)
        if finish is None:
            assert got == want  # same readings, ids and rates, bit for bit
            continue
        deferred += 1
        assert not want.tracked and got.tracked  # sent: the tracked readings of the same landmarks
        assert [lm.track_id for lm in got.landmarks] == [lm.track_id for lm in want.landmarks]
        assert finish() == want  # the scan itself reads as process() did
    assert deferred >= 2


def test_a_scan_never_finished_is_done_on_the_next_frame():
    _, pipe = _pipes()
    frames = list(moving_sequence(8))
    finishes = [pipe.process_scan_later(img, t_s=i / 30)[1] for i, img in enumerate(frames[:5])]
    assert finishes[:4] == [None] * 4 and finishes[4] is not None  # 0 scanned, 1-3 tracked, 4's scan due
    result, finish = pipe.process_scan_later(frames[5], t_s=5 / 30)
    assert finish is None and not result.tracked and len(result.landmarks) == 2


def test_a_newcomer_is_sent_one_frame_after_the_scan_that_found_it():
    now, later = _pipes()
    first_now = first_later = None
    for i, img in enumerate(moving_sequence(12, newcomer_at=2)):
        want = now.process(img, t_s=i / 30)
        got, finish = later.process_scan_later(img, t_s=i / 30)
        if finish is not None:
            finish()
        if first_now is None and len(want.landmarks) == 3:
            first_now = i
        if first_later is None and len(got.landmarks) == 3:
            first_later = i
    assert first_now is not None and first_later == first_now + 1


def test_a_defect_in_the_scan_left_for_later_is_that_frame_s_and_restarts_the_tracks(monkeypatch):
    import pytest

    from rangebearing.core import pipeline as pipeline_module
    from rangebearing.core.guarded import DetectorFault, scan_later_or_skip

    _, pipe = _pipes()
    frames = list(moving_sequence(5))
    for i, img in enumerate(frames[:4]):
        assert scan_later_or_skip(pipe, img, i / 30)[1] is None
    result, scan = scan_later_or_skip(pipe, frames[4], 4 / 30)
    assert scan is not None and len(result.landmarks) == 2

    def broken(*args, **kwargs):
        raise IndexError("a defect")

    monkeypatch.setattr(pipeline_module, "refine", broken)  # only the full scan refines
    with pytest.raises(DetectorFault, match="IndexError"):
        scan()
    assert pipe._tracks == [] and pipe.next_track_id == 2  # tracks restarted, ids keep counting
