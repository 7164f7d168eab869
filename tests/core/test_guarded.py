"""A defect in the detector on one frame is that frame's: skipped and counted, the run goes on."""

from __future__ import annotations

import numpy as np
import pytest

from rangebearing.config import Config
from rangebearing.core.guarded import process_or_skip
from rangebearing.core.pipeline import Pipeline
from rangebearing.errors import DetectorFault, FrameError


def test_a_defect_becomes_this_frames_fault_naming_where_and_tracks_restart(monkeypatch):
    pipe = Pipeline(Config().pipeline)
    frame = np.full((480, 640, 3), 128, np.uint8)
    resets = []
    monkeypatch.setattr(pipe, "reset", lambda new_run=False: resets.append(new_run))

    def broken(image, t_s=None, search=None):
        return [1, 2][5]  # an index past an array's end, as a defect would

    monkeypatch.setattr(pipe, "process", broken)
    with pytest.raises(DetectorFault, match=r"IndexError at test_guarded.py:\d+ in broken") as info:
        process_or_skip(pipe, frame)
    assert isinstance(info.value, FrameError) and isinstance(info.value.__cause__, IndexError)
    assert resets == [False]  # ids keep counting


def test_a_bad_frame_is_still_a_plain_frame_error_and_tracks_stay():
    pipe = Pipeline(Config().pipeline)
    with pytest.raises(FrameError) as info:
        process_or_skip(pipe, np.zeros((4, 4), np.float32))
    assert not isinstance(info.value, DetectorFault)


def test_a_good_frame_passes_through():
    pipe = Pipeline(Config().pipeline)
    assert process_or_skip(pipe, np.full((480, 640, 3), 128, np.uint8)).landmarks == ()
