"""Capturer against picamera2's dispatch semantics: a job signalled after its capture timed out is not leaked."""

from __future__ import annotations

import concurrent.futures
import threading
from typing import Any, List, Optional

import pytest

from rangebearing.config import SourceConfig
from rangebearing.errors import FrameError
from rangebearing.sources import Picamera2Source
from rangebearing.sources.camera_capture import Capturer, LateRequest, Notes


class Request:
    def __init__(self) -> None:
        self.released = 0

    def release(self) -> None:
        self.released += 1
        if self.released > 1:
            raise RuntimeError("CompletedRequest: lock now has negative ref_count")  # request.py 117-118


class Job:
    """job.py's Job: a Future; ``signal`` calls the signal_function after the result is set."""

    def __init__(self, signal_function: Any) -> None:
        self._future: concurrent.futures.Future = concurrent.futures.Future()
        self._signal_function = signal_function

    def get_result(self, timeout: Optional[float] = None) -> Any:
        return self._future.result(timeout=timeout)

    def complete(self, request: Request) -> None:
        self._future.set_result(request)
        if self._signal_function:
            self._signal_function(self)


class RacingCamera:
    """The race in picamera2.py's process_requests: the job is executed (popped off the job list, out of
    reach of cancel_all_and_flush) when the capture's wait runs out; signal() comes after, or just before."""

    def __init__(self, signal_first: bool = False) -> None:
        self.signal_first = signal_first
        self.jobs: List[Job] = []
        self.requests: List[Request] = []

    def capture_request(self, wait: Any = None, signal_function: Any = None, flush: Any = None) -> Any:
        job = Job(signal_function)
        self.jobs.append(job)
        request = Request()
        self.requests.append(request)
        if self.signal_first:
            job.complete(request)  # signalled, but the caller's wait had already run out
        raise concurrent.futures.TimeoutError()

    def late_signals(self) -> None:
        for job, request in zip(self.jobs, self.requests):
            if not job._future.done():
                job.complete(request)


def capturer() -> Capturer:
    return Capturer(Notes(0), timeout_s=0.5)


@pytest.mark.parametrize("signal_first", [False, True])
def test_a_request_completed_after_its_capture_timed_out_is_released_once(signal_first: bool) -> None:
    cam = RacingCamera(signal_first)
    cap = capturer()
    with pytest.raises(concurrent.futures.TimeoutError):
        cap.request(cam.capture_request)
    cam.late_signals()
    assert [r.released for r in cam.requests] == [1]


def test_a_request_the_capture_returned_is_left_to_the_caller() -> None:
    requests: List[Request] = []

    def capture_request(wait: Any = None, signal_function: Any = None) -> Request:
        job = Job(signal_function)
        requests.append(Request())
        job.complete(requests[-1])  # signalled in the event loop before the caller's wait returns
        return job.get_result(wait)

    got = capturer().request(capture_request)
    assert got is requests[0] and got.released == 0


def test_a_capture_without_signal_function_still_gets_its_wait() -> None:
    waits: List[Any] = []

    def capture_request(wait: Any = None) -> Request:  # a stand-in written from the manual's wait= examples
        waits.append(wait)
        return Request()

    cap = capturer()
    assert isinstance(cap.request(capture_request), Request)
    assert isinstance(cap.request(capture_request), Request)
    assert waits == [0.5, 0.5] and cap.takes_wait and not cap.takes_signal


def test_a_capture_with_no_keywords_at_all() -> None:
    calls: List[int] = []

    def capture_request() -> Request:  # picamera2 before 0.3.9
        calls.append(1)
        return Request()

    cap = capturer()
    assert isinstance(cap.request(capture_request), Request)
    assert isinstance(cap.request(capture_request), Request)
    assert len(calls) == 2 and not cap.takes_wait and not cap.takes_signal


def test_a_job_that_failed_is_not_released() -> None:
    late = LateRequest(Notes(0))
    job = Job(late)
    late.abandon()
    job._future.set_exception(concurrent.futures.CancelledError())  # cancel_all_and_flush got it: no request
    late(job)  # must not raise in picamera2's event loop


def test_on_the_clean_room_fake_a_request_signalled_after_the_timeout_is_given_back(
        alt_picamera2: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    _, rig = alt_picamera2
    import picamera2.job as job_module

    armed, delayed, go_on = threading.Event(), threading.Event(), threading.Event()
    signal = job_module.Job.signal

    def late_signal(job: Any) -> None:  # the event loop executed the job (off the job list), signals it late
        if armed.is_set() and not delayed.is_set():
            delayed.set()
            go_on.wait(60)
        signal(job)

    monkeypatch.setattr(job_module.Job, "signal", late_signal)
    cfg = SourceConfig(width_px=40, height_px=30, fps=30.0, timeout_s=0.3, retries=3)
    source = Picamera2Source(cfg, sleep=lambda s: None, in_place=True)
    source.open()
    try:
        assert source.read() is not None
        armed.set()
        with pytest.raises(FrameError, match="no frame within"):
            source.read()
        assert delayed.is_set()
        go_on.set()  # the result lands in the Future after cancel_all_and_flush() could reach the job
        for _ in range(200):
            if rig.held() == 0:
                break
            rig.RIG.wait_ticks(1)
        assert rig.held() == 0  # given back by the capture's signal_function
        for _ in range(6):
            assert source.read() is not None
        assert rig.held() == 1
    finally:
        go_on.set()
        source.close()
