"""The daemon's own process: the collector run after the send, wake-ups without timer slack."""

from __future__ import annotations

import ctypes
import gc

import pytest

from rangebearing.daemon.process import SAFETY_FACTOR, THRESHOLDS, Collector, precise_wakeups


@pytest.fixture
def collector_restored():
    was = gc.isenabled(), gc.get_threshold()
    yield
    gc.unfreeze()
    gc.set_threshold(*was[1])
    if was[0]:
        gc.enable()
    else:
        gc.disable()


def test_the_first_frame_freezes_start_up_and_leaves_the_automatic_collector_a_safety_net(collector_restored):
    gc.disable()  # as `run` starts
    Collector().frame_sent(first=True)
    assert gc.isenabled() and gc.get_freeze_count() > 1000
    assert gc.get_threshold() == (THRESHOLDS[0] * SAFETY_FACTOR, *THRESHOLDS[1:])


def test_the_loop_collects_young_objects_past_cpythons_threshold_and_not_before(collector_restored):
    c = Collector()
    c.frame_sent(first=True)
    gc.collect()
    c.frame_sent(first=False)  # nothing young yet
    assert c.collections == [0, 0, 0]
    kept = [[i] for i in range(THRESHOLDS[0] + 50)]  # container objects, alive: the young count passes 700
    assert gc.get_count()[0] > THRESHOLDS[0]
    c.frame_sent(first=False)
    assert sum(c.collections) == 1 and gc.get_count()[0] < THRESHOLDS[0]
    assert len(kept) == THRESHOLDS[0] + 50


def test_a_collection_after_more_than_ten_young_ones_takes_the_middle_generation_as_cpython_would(
        collector_restored):
    c = Collector()
    c.frame_sent(first=True)
    gc.collect()
    kept = []
    for _ in range(THRESHOLDS[1] + 2):  # count[1] > threshold[1]: the twelfth is a generation-1 collection
        kept.append([[i] for i in range(THRESHOLDS[0] + 10)])
        c.frame_sent(first=False)
    assert c.collections == [THRESHOLDS[1] + 1, 1, 0]


def test_precise_wakeups_sets_the_threads_timer_slack():
    prctl = ctypes.CDLL(None).prctl
    before = prctl(30, 0, 0, 0, 0)  # PR_GET_TIMERSLACK
    try:
        assert precise_wakeups(1000)
        assert prctl(30, 0, 0, 0, 0) == 1000
    finally:
        prctl(29, before, 0, 0, 0)
