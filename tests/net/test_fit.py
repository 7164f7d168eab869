"""A frame whose datagram would not fit one packet still sends a heartbeat: the nearest
landmarks that fit, and how many were left out."""

from __future__ import annotations

import dataclasses

import pytest

from rangebearing.cli.common import format_reading
from rangebearing.net.fit import MTU_PAYLOAD_BYTES, encode_fitting
from rangebearing.net.protocol import decode_reading, encode_reading

from .factories import make_landmark


def test_a_datagram_that_fits_is_unchanged() -> None:
    lms = [make_landmark(range_m=0.5 + i) for i in range(3)]
    assert encode_fitting("zumo", 1, 2.0, lms, 30.0, 0) == encode_reading("zumo", 1, 2.0, lms, 30.0, 0)
    assert decode_reading(encode_fitting("zumo", 1, 2.0, lms)).omitted is None


def test_too_many_landmarks_send_the_nearest_that_fit_and_a_count() -> None:
    lms = [make_landmark(range_m=round(3.0 - 0.01 * i, 4), x_px=100.0 + i) for i in range(60)]
    assert len(encode_reading("zumo", 1, 2.0, lms)) > MTU_PAYLOAD_BYTES
    data = encode_fitting("zumo", 1, 2.0, lms, fps=30.0, dropped=5)
    assert len(data) <= MTU_PAYLOAD_BYTES
    r = decode_reading(data)
    sent = len(r.landmarks)
    assert 0 < sent < 60 and r.omitted == 60 - sent
    nearest = sorted(lm.range_m for lm in lms)[:sent]
    assert sorted(lm.range_m for lm in r.landmarks) == nearest
    # one more would not have fitted: the cut is the largest possible
    more = sorted(lms, key=lambda lm: lm.range_m)[: sent + 1]
    assert len(encode_reading("zumo", 1, 2.0, more, 30.0, 5, omitted=60 - sent - 1)) > MTU_PAYLOAD_BYTES
    assert format_reading(r).endswith(f"[30.0 fps, 5 dropped, {60 - sent} more not sent: datagram full]")


def test_when_no_landmark_fits_a_heartbeat_still_goes_out() -> None:
    lms = [make_landmark()] * 4
    data = encode_fitting("zumo", 7, 2.0, lms, max_bytes=len(encode_reading("zumo", 7, 2.0, omitted=4)))
    r = decode_reading(data)
    assert r.seq == 7 and r.landmarks == () and r.omitted == 4


@pytest.mark.parametrize("n", [0, 1, 17])
def test_the_cut_never_exceeds_the_budget(n: int) -> None:
    lm = dataclasses.replace(make_landmark(), d_v_m=-12.345678, d_h_m=-12.345678, l_px=1279.987)
    for budget in range(250, 1500, 97):
        data = encode_fitting("robot-with-a-long-name", 2**40, 1.7e9, [lm] * n, 29.97, 123, max_bytes=budget)
        assert len(data) <= max(budget, len(encode_reading("robot-with-a-long-name", 2**40, 1.7e9, (), 29.97,
                                                            123, omitted=n)))
