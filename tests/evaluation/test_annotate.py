"""Annotated frames: sigma error bars and track ids."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rangebearing.core.types import FrameResult, Landmark
from rangebearing.evaluation.annotate import YELLOW, annotate, error_bars, labels

LM = Landmark(0.5, 0.0, 0.5, 0.0, 70.0, (320.0, 200.0), (320.0, 270.0), 44.0, (298, 190, 44, 90), True,
              range_sigma_m=0.005, bearing_sigma_rad=0.002, visible=1.0, track_id=7,
              range_rate_mps=-0.1, bearing_rate_radps=0.2)


def test_error_bars_by_hand():
    bearing_px, range_px = error_bars(LM)
    # 70 px for 55 mm at 0.5 m: 636 px per radian; L changes by 1 % for a 1 % range change
    assert bearing_px == pytest.approx(0.002 * 70.0 * 0.5 / 0.055)
    assert range_px == pytest.approx(0.5 * 70.0 * 0.01)


def test_labels_carry_the_id_sigmas_and_rates():
    first, rates = labels(LM)
    assert first.startswith("id 7 0.500+-0.005 m") and "+-0.1 deg" in first
    assert rates == "-0.10 m/s +11 deg/s"
    assert labels(dataclasses.replace(LM, track_id=-1, range_rate_mps=None, bearing_rate_radps=None,
                                      visible=0.6)) == ["0.500+-0.005 m +0.0+-0.1 deg", "60% visible"]


def test_the_frame_gets_yellow_bars_and_stays_untouched():
    frame = np.full((480, 640, 3), 90, np.uint8)
    out = annotate(frame, FrameResult(landmarks=(LM,)))
    assert (frame == 90).all()  # a copy is drawn on
    yellow = (out == np.array(YELLOW, np.uint8)).all(axis=2)
    bearing_px = round(error_bars(LM)[0])
    assert yellow[235, 320 - bearing_px:320 + bearing_px + 1].all()  # the bearing bar across the middle
