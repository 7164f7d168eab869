"""Fault injection through the fake camera: readings resume, or the exit is clean and prompt.

Each test prints the figure it measures (run with ``-s``): gaps, recovery times, exit times.
Budgets are short (a fraction of a second to a few seconds) so the file runs in ~15 s. Waits for readings
and for the daemon to reach a state are events with generous deadlines (a loaded machine only makes them
slower); what is timed is only what a test asserts about time.
"""

from __future__ import annotations

import dataclasses
import threading
import time
from typing import Any, Callable, List

import numpy as np
import pytest

from rangebearing.config import Config, SourceConfig
from rangebearing.core.types import Landmark
from rangebearing.daemon.loop import Daemon
from rangebearing.net.fit import MTU_PAYLOAD_BYTES
from rangebearing.net.protocol import decode_reading
from rangebearing.net.publisher import MemoryPublisher

from .test_loop import RecordingNotifier, opener

GREY = np.full((480, 640, 3), 128, np.uint8)
WAIT_S = 60.0  # the longest a test waits for readings or a state: ends at once when they come


def cfg(**source: Any) -> Config:
    fields = {"kind": "picamera2", "fps": 30.0, "timeout_s": 0.25, "retries": 8, "open_timeout_s": 5.0, **source}
    return dataclasses.replace(Config(), source=dataclasses.replace(SourceConfig(), **fields))


class Run:
    """The daemon in a thread, every reading's arrival time noted."""

    def __init__(self, config: Config, **kw: Any) -> None:
        self.times: List[float] = []
        self.arrived = threading.Condition()
        self.notifier = RecordingNotifier()
        self.daemon = Daemon(config, opener, lambda c: MemoryPublisher(), self.notifier, **kw)
        self.daemon.echo = self._echo
        self.status: List[int] = []
        self.thread = threading.Thread(target=self._run, daemon=True)

    def _echo(self, payload: bytes) -> None:
        with self.arrived:
            self.times.append(time.monotonic())
            self.arrived.notify_all()

    def _run(self) -> None:
        try:
            self.status.append(self.daemon.run())
        finally:
            with self.arrived:
                self.arrived.notify_all()  # a waiter for readings that will never come: wake it

    def __enter__(self) -> Run:
        self.thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.daemon.stop()
        self.thread.join(10)

    def wait_for(self, n: int, timeout_s: float = WAIT_S) -> None:
        with self.arrived:
            self.arrived.wait_for(lambda: len(self.times) >= n or not self.thread.is_alive(), timeout_s)
        assert len(self.times) >= n, f"only {len(self.times)} readings"

    def stop(self) -> int:
        t0 = time.monotonic()
        self.daemon.stop()
        self.thread.join(5)
        assert not self.thread.is_alive() and time.monotonic() - t0 < 2.0
        return self.status[0]


def grey(seq: int, h: int, w: int) -> np.ndarray:
    return np.full((h, w, 3), 128, np.uint8)


def test_an_error_every_fifth_capture_is_retried_and_readings_go_on(fake_picamera2: Any) -> None:
    world = fake_picamera2.WORLD
    world.producer = grey
    real = fake_picamera2.Picamera2.capture_request
    calls = [0]

    def flaky(self: Any, *args: Any, **kw: Any) -> Any:
        calls[0] += 1
        if calls[0] % 5 == 0:
            raise RuntimeError("Camera frontend has timed out!")  # what libcamera says
        return real(self, *args, **kw)

    fake_picamera2.Picamera2.capture_request = flaky
    with Run(cfg()) as run:
        run.wait_for(40)
        assert run.stop() == 0
    assert run.daemon.guard.faults >= 7 and run.daemon.guard.reopens == 0
    gap = max(np.diff(run.times))
    print(f"\nerror every 5th capture: {len(run.times)} readings, longest gap {gap * 1000:.0f} ms")
    assert gap < 0.5


def test_a_stall_that_clears_in_3_s_is_ridden_out(fake_picamera2: Any) -> None:
    world = fake_picamera2.WORLD
    world.producer = grey
    with Run(cfg(timeout_s=0.5, retries=8)) as run:  # budget 4 s: reopened at 2 s, never given up
        run.wait_for(5)
        world.set_stalled(True)
        t_stall = time.monotonic()
        threading.Timer(3.0, world.set_stalled, args=(False,)).start()
        n = len(run.times)
        run.wait_for(n + 5)
        resumed = next(t for t in run.times if t > t_stall + 2.9)
        assert run.stop() == 0
    print(f"\nstall of 3 s: first reading {resumed - t_stall - 3.0:.2f} s after it cleared")
    assert resumed - t_stall < 4.0 and run.daemon.stats.bad_frames >= 3


def test_a_stall_that_never_clears_ends_cleanly_within_the_budget(fake_picamera2: Any, caplog: Any) -> None:
    world = fake_picamera2.WORLD
    world.producer = grey
    with Run(cfg(timeout_s=0.25, retries=8)) as run:  # budget 2 s
        run.wait_for(3)
        world.set_stalled(True)
        t_stall = time.monotonic()
        run.thread.join(WAIT_S)
        took = time.monotonic() - t_stall
    assert run.status == [1] and 2.0 <= took < 3.5, took
    assert run.daemon.guard.reopens == 1
    assert "exiting for the service manager" in caplog.text
    print(f"\nstall that never clears: clean exit 1 after {took:.2f} s (budget 2 s)")


def test_a_camera_missing_at_start_then_present_starts_reading(fake_picamera2: Any) -> None:
    world = fake_picamera2.WORLD
    world.producer = grey
    world.num_cameras = 0
    back = []

    def plug_in() -> None:
        back.append(time.monotonic())
        world.num_cameras = 1

    threading.Timer(1.7, plug_in).start()  # between two retries
    with Run(cfg(open_timeout_s=10.0)) as run:
        run.wait_for(3)
        assert run.stop() == 0
    took = run.times[0] - back[0]
    print(f"\ncamera back at start: first reading {took:.2f} s later")
    assert run.notifier.calls[0] == "READY" and took < 3.0


def test_a_camera_lost_while_running_exits_and_a_restart_finds_it(fake_picamera2: Any) -> None:
    world = fake_picamera2.WORLD
    world.producer = grey
    with Run(cfg(timeout_s=0.25, retries=4)) as run:  # budget 1 s
        run.wait_for(3)
        world.set_stalled(True)
        world.num_cameras = 0  # unplugged: the reopen finds nothing
        run.thread.join(WAIT_S)
    assert run.status == [1]
    world.stalled, world.num_cameras = False, 1  # plugged back: systemd's restart is a new run
    with Run(cfg()) as again:
        again.wait_for(3)
        assert again.stop() == 0


def test_sigterm_during_camera_back_off_exits_0_promptly(fake_picamera2: Any) -> None:
    fake_picamera2.WORLD.num_cameras = 0
    real = fake_picamera2.Picamera2.global_camera_info
    asked = threading.Semaphore(0)

    def counted() -> Any:
        asked.release()
        return real()

    fake_picamera2.Picamera2.global_camera_info = staticmethod(counted)
    with Run(cfg(open_timeout_s=30.0)) as run:
        for _ in range(2):  # a second attempt: the first failed and its back-off ran
            assert asked.acquire(timeout=WAIT_S)
        assert run.stop() == 0


def test_a_wedged_capture_call_does_not_need_sigkill(fake_picamera2: Any) -> None:
    world = fake_picamera2.WORLD
    world.producer = grey
    real = fake_picamera2.Picamera2.capture_request
    wedge, wedged = threading.Event(), threading.Event()

    def sometimes_wedged(self: Any, *args: Any, **kw: Any) -> Any:
        if wedge.is_set():
            wedged.set()
            world.release.wait()  # ignores its timeout: blocked in the camera stack
        return real(self, *args, **kw)

    fake_picamera2.Picamera2.capture_request = sometimes_wedged
    with Run(cfg(timeout_s=0.25, retries=40)) as run:  # a 10 s budget: only the stop can end this run
        run.wait_for(3)
        wedge.set()
        assert wedged.wait(WAIT_S)  # the capture thread is stuck in the call
        assert run.stop() == 0
    assert run.daemon.guard.wedged  # the CLI leaves with os._exit instead of joining the thread


def test_frames_of_another_aspect_ratio_are_said_once_and_end_with_status_2(fake_picamera2: Any,
                                                                            caplog: Any) -> None:
    fake_picamera2.WORLD.producer = grey
    with Run(cfg(width_px=640, height_px=360)) as run:  # a 16:9 mode, intrinsics for 4:3
        run.thread.join(WAIT_S)
    assert run.status == [2] and "READY" not in run.notifier.calls and "STATUS" in run.notifier.calls
    errors = [r for r in caplog.records if r.levelname == "ERROR"]
    assert len(errors) == 1 and "aspect ratio" in errors[0].getMessage()


def test_a_frame_with_too_many_landmarks_still_sends_a_heartbeat(fake_picamera2: Any) -> None:
    fake_picamera2.WORLD.producer = grey
    lm = Landmark(0.5, 0.1, 0.49, 0.05, 60.0, (300.0, 200.0), (300.5, 260.0), 40.0, (280, 190, 42, 80), True)
    crowd = tuple(dataclasses.replace(lm, range_m=0.3 + 0.05 * i) for i in range(40))
    pub = MemoryPublisher()
    daemon = Daemon(cfg(), opener, lambda c: pub, RecordingNotifier())
    real_process = daemon._pipe.process
    daemon._pipe.process = lambda image, **kw: dataclasses.replace(real_process(image, **kw), landmarks=crowd)  # type: ignore
    daemon.echo = lambda payload: len(pub.payloads) >= 3 and daemon.stop()
    assert daemon.run() == 0
    for payload in pub.payloads:
        r = decode_reading(payload)
        assert len(payload) <= MTU_PAYLOAD_BYTES and 0 < len(r.landmarks) < 40
        assert r.omitted == 40 - len(r.landmarks) and min(x.range_m for x in r.landmarks) == pytest.approx(0.3)


def test_no_reload_can_end_the_daemon(static_clip: Any) -> None:
    from .test_loop import recorded_cfg

    failures: List[Callable[[], Config]] = []
    for exc in (RuntimeError("boom"), RecursionError(), MemoryError(), KeyError("x"), UnicodeError("u")):
        def reload(exc: BaseException = exc) -> Config:
            raise exc
        failures.append(reload)
    calls = [0]

    def reload() -> Config:
        calls[0] += 1
        return failures[calls[0] % len(failures)]()

    seen: List[bytes] = []
    daemon = Daemon(recorded_cfg(static_clip, loop=True), opener, lambda c: MemoryPublisher(), RecordingNotifier(),
                    reload=reload)

    def echo(payload: bytes) -> None:
        seen.append(payload)
        if len(seen) < 40:
            daemon.request_reload()
        else:
            daemon.stop()

    daemon.echo = echo
    assert daemon.run() == 0
    assert len(seen) == 40 and calls[0] >= 39


def test_watchdog_pings_follow_frames_within_a_second(static_clip: Any) -> None:
    """Item 11: with WatchdogSec=20 a ping every 10 s would let a stall be killed 10 s after its last frame."""
    from .test_loop import recorded_cfg

    note = RecordingNotifier(watchdog_s=20.0)
    config = recorded_cfg(static_clip, loop=True)
    config = dataclasses.replace(config, source=dataclasses.replace(config.source, fps=20.0))
    daemon = Daemon(config, opener, lambda c: MemoryPublisher(), note)
    first: List[float] = []

    def echo(payload: bytes) -> None:  # 2.6 s of frames, counted from the first (start-up may be slow)
        first.append(first[0] if first else time.monotonic())
        if time.monotonic() - first[0] >= 2.6:
            daemon.stop()

    daemon.echo = echo
    assert daemon.run() == 0
    assert note.calls.count("WATCHDOG") >= 2
