"""The capture loop in-process: readings, faults survived, and the Picamera2 source via the fake."""

from __future__ import annotations

import dataclasses
import math
import shutil
import socket
import threading
import time
from pathlib import Path
from typing import List

import cv2
import numpy as np
import pytest

from rangebearing.config import Config, PublishConfig, SourceConfig
from rangebearing.daemon.loop import Daemon
from rangebearing.net.protocol import decode_reading
from rangebearing.net.publisher import MemoryPublisher, UdpPublisher
from rangebearing.sources.factory import open_source
from rangebearing.synth import render
from tests.conftest import STATIC_SCENE


class RecordingNotifier:
    """Stands in for sdnotify.Notifier and remembers what the daemon said."""

    def __init__(self, watchdog_s: float = 0.0) -> None:
        self.calls: List[str] = []
        self._wd = watchdog_s

    def ready(self, status=None):
        self.calls.append("READY")

    def watchdog(self):
        self.calls.append("WATCHDOG")

    def status(self, text):
        self.calls.append("STATUS")

    def stopping(self):
        self.calls.append("STOPPING")

    def reloading(self):
        self.calls.append("RELOADING")

    def watchdog_interval_s(self):
        return self._wd or None


def opener(cfg, sleep):
    return open_source(cfg.source, cfg.camera, sleep=sleep)


def recorded_cfg(path: Path, **source) -> Config:
    src = dataclasses.replace(SourceConfig(), kind="recorded", path=str(path), fps=0.0, **source)
    return dataclasses.replace(Config(), source=src)


def assert_matches_static_truth(payload: bytes) -> None:
    reading = decode_reading(payload)
    truth = sorted(STATIC_SCENE.landmarks, key=lambda lm: lm.range_m)
    assert len(reading.landmarks) == len(truth)
    for got, want in zip(reading.landmarks, truth):
        assert got.range_m == pytest.approx(want.range_m, rel=0.02)
        assert got.bearing_rad == pytest.approx(want.bearing_rad, abs=math.radians(0.3))


def test_every_frame_of_a_clip_is_published_with_its_readings(static_clip):
    pub, note = MemoryPublisher(), RecordingNotifier(watchdog_s=1e-6)
    daemon = Daemon(recorded_cfg(static_clip), opener, lambda cfg: pub, note)
    assert daemon.run() == 0
    assert len(pub.payloads) == 12 and pub.closed
    assert [decode_reading(p).seq for p in pub.payloads] == list(range(12))
    for p in pub.payloads:
        assert_matches_static_truth(p)
    assert note.calls[0] == "READY" and "WATCHDOG" in note.calls and note.calls[-1] == "STOPPING"
    s = daemon.summary()
    assert s.frames == 12 and s.bad_frames == 0 and s.latency_ms_p99 > 0


def test_a_corrupt_frame_is_skipped_and_counted(static_clip, tmp_path):
    clip = tmp_path / "clip"
    shutil.copytree(static_clip, clip)
    (clip / "000005b.png").write_bytes(b"\x89PNG\r\n\x1a\n not really")
    cv2.imwrite(str(clip / "000006b.png"), np.zeros((4, 4, 3), np.uint8))  # too small to be a frame
    pub = MemoryPublisher()
    daemon = Daemon(recorded_cfg(clip), opener, lambda cfg: pub, RecordingNotifier())
    assert daemon.run() == 0
    assert daemon.stats.bad_frames == 2
    assert len(pub.payloads) == 12


def test_a_missing_udp_receiver_never_stops_the_daemon(static_clip):
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        dead_port = s.getsockname()[1]
    cfg = dataclasses.replace(
        recorded_cfg(static_clip, loop=True), publish=PublishConfig(unicast=(("127.0.0.1", dead_port),))
    )
    publishers = []

    def open_pub(c):
        publishers.append(UdpPublisher(c.publish))
        return publishers[-1]

    seen = []
    daemon = Daemon(cfg, opener, open_pub, RecordingNotifier())
    daemon.echo = lambda payload: (seen.append(payload), len(seen) >= 30 and daemon.stop())
    assert daemon.run() == 0
    assert len(seen) == 30
    stats = publishers[0].stats
    # every frame was sent or counted as refused (how many ICMP refusals arrive is the kernel's rate limit)
    assert stats.total_sent + stats.total_errors == 30


def test_stop_from_another_thread_ends_a_paced_source_promptly(static_clip):
    cfg = recorded_cfg(static_clip, loop=True)
    cfg = dataclasses.replace(cfg, source=dataclasses.replace(cfg.source, fps=2.0))  # long waits between frames
    two_sent = threading.Event()
    sent: List[bytes] = []
    daemon = Daemon(cfg, opener, lambda c: MemoryPublisher(), RecordingNotifier(),
                    echo=lambda p: (sent.append(p), len(sent) >= 2 and two_sent.set()))
    t = threading.Thread(target=daemon.run)
    t.start()
    assert two_sent.wait(60)  # the loop is now inside a 0.5 s wait for the next frame
    t0 = time.monotonic()
    daemon.stop()
    t.join(5)
    assert not t.is_alive() and time.monotonic() - t0 < 1.0


def picamera_cfg(**source) -> Config:
    """A fake camera config; tests that wait for frames ask ``retries=50`` (10 s: each frame is rendered)."""
    fields = {"kind": "picamera2", "fps": 30.0, "timeout_s": 0.2, "retries": 3, **source}
    src = dataclasses.replace(SourceConfig(), **fields)
    return dataclasses.replace(Config(), source=src)


def static_rgb(seq: int, height: int, width: int) -> np.ndarray:
    bgr = render(STATIC_SCENE, np.random.default_rng(seq))
    return np.ascontiguousarray(bgr[:, :, ::-1])  # the fake's producer speaks RGB, like the scene


def test_picamera2_source_runs_through_the_loop_and_survives_a_capture_timeout(fake_picamera2):
    world = fake_picamera2.WORLD
    world.producer = static_rgb
    seen: List[bytes] = []
    daemon = Daemon(picamera_cfg(retries=50), opener, lambda c: MemoryPublisher(), RecordingNotifier())

    def unstall_after_a_timeout() -> None:  # not after a fixed time: a loaded machine may not have asked yet
        deadline = time.monotonic() + 60.0
        while daemon.stats.bad_frames < 1 and time.monotonic() < deadline:
            time.sleep(0.01)
        world.set_stalled(False)

    def echo(payload: bytes) -> None:
        seen.append(payload)
        if len(seen) == 3:  # stall the sensor once: one capture times out, then frames resume
            world.set_stalled(True)
            threading.Thread(target=unstall_after_a_timeout, daemon=True).start()
        if len(seen) >= 8:
            daemon.stop()

    daemon.echo = echo
    assert daemon.run() == 0
    assert len(seen) == 8
    assert daemon.stats.bad_frames >= 1  # the timed-out capture, skipped and counted
    for p in seen:
        assert_matches_static_truth(p)  # RGB888 arrives as BGR and is used as such


def test_a_missing_camera_ends_the_run_with_a_failure(fake_picamera2, caplog):
    fake_picamera2.WORLD.num_cameras = 0
    daemon = Daemon(picamera_cfg(retries=1, open_timeout_s=0.5), opener, lambda c: MemoryPublisher(),
                    RecordingNotifier())
    t0 = time.monotonic()
    assert daemon.run() == 1
    assert time.monotonic() - t0 < 3.0
    assert "no camera 0" in caplog.text


def test_a_camera_that_keeps_timing_out_ends_the_run(fake_picamera2, caplog):
    fake_picamera2.WORLD.stalled = True
    daemon = Daemon(picamera_cfg(retries=2), opener, lambda c: MemoryPublisher(), RecordingNotifier())
    assert daemon.run() == 1
    assert "exiting for the service manager" in caplog.text


def test_reloads_swap_the_publisher_and_survive_a_source_that_will_not_open(static_clip, tmp_path, caplog):
    cfg_file = tmp_path / "c.yaml"
    good = f'source: {{kind: recorded, path: "{static_clip}", fps: 0, loop: true}}\npublish: {{robot_id: %s}}\n'
    cfg_file.write_text(good % "alpha")
    publishers: List[MemoryPublisher] = []

    def open_pub(c):
        publishers.append(MemoryPublisher())
        return publishers[-1]

    from rangebearing.config import load_config

    daemon = Daemon(load_config(cfg_file), opener, open_pub, RecordingNotifier(), reload=lambda: load_config(cfg_file))
    robots: List[str] = []

    def echo(payload: bytes) -> None:
        robots.append(decode_reading(payload).robot)
        n = len(robots)
        if n == 5:  # a new robot id: a new publisher, the old one closed
            cfg_file.write_text(good % "beta")
            daemon.request_reload()
        elif n == 10:  # a source that cannot open: rejected, the old source reopened, the loop goes on
            cfg_file.write_text('source: {kind: recorded, path: "/nonexistent/clip"}\npublish: {robot_id: gamma}\n')
            daemon.request_reload()
        elif n == 20:
            daemon.stop()

    daemon.echo = echo
    assert daemon.run() == 0
    assert robots[:5] == ["alpha"] * 5 and robots[5:] == ["beta"] * 15
    assert "reload rejected: cannot open the new frame source" in caplog.text
    assert len(publishers) == 3 and all(p.closed for p in publishers)  # none leaked, the rejected one included


def test_track_ids_hold_over_frames_and_are_not_reused_after_a_reload(static_clip, tmp_path):
    cfg_file = tmp_path / "c.yaml"
    base = f'source: {{kind: recorded, path: "{static_clip}", fps: 0, loop: true}}\n'
    cfg_file.write_text(base)

    from rangebearing.config import load_config

    daemon = Daemon(load_config(cfg_file), opener, lambda c: MemoryPublisher(), RecordingNotifier(),
                    reload=lambda: load_config(cfg_file))
    ids: List[List[int]] = []

    def echo(payload: bytes) -> None:
        ids.append(sorted(lm.track_id for lm in decode_reading(payload).landmarks))
        if len(ids) == 6:  # another pipeline (window tracking off): a new Pipeline, the id counter carried on
            cfg_file.write_text(base + "detection: {tracking: false}\n")
            daemon.request_reload()
        elif len(ids) == 14:
            daemon.stop()

    daemon.echo = echo
    assert daemon.run() == 0
    n = len(STATIC_SCENE.landmarks)
    first, last = ids[0], ids[-1]
    assert first == list(range(n)) and all(frame == first for frame in ids[:6])  # a still scene keeps its ids
    assert last == list(range(n, 2 * n)) and ids[-4:] == [last] * 4  # fresh ids after the reload, none reused


def test_a_paced_recording_stays_paced_after_the_open_budget(static_clip):
    """The open budget bounds opening; frames past it are still never served before they are due."""
    cfg = recorded_cfg(static_clip, loop=True)
    cfg = dataclasses.replace(cfg, source=dataclasses.replace(cfg.source, fps=5.0, open_timeout_s=0.05))
    ahead_s: List[float] = []
    daemon = Daemon(cfg, opener, lambda c: MemoryPublisher(), RecordingNotifier())

    def echo(payload: bytes) -> None:
        ahead_s.append(decode_reading(payload).t - time.time())  # > 0: a frame sent before it was captured
        if len(ahead_s) >= 4:
            daemon.stop()

    daemon.echo = echo
    assert daemon.run() == 0
    assert len(ahead_s) == 4 and max(ahead_s) < 0.01


def test_recorded_frames_are_read_in_the_loop_thread_camera_frames_in_a_reader(static_clip, fake_picamera2):
    names = {}
    for key, cfg in (("recorded", recorded_cfg(static_clip)), ("camera", picamera_cfg(retries=50))):
        if key == "camera":
            fake_picamera2.WORLD.producer = static_rgb
        daemon = Daemon(cfg, opener, lambda c: MemoryPublisher(), RecordingNotifier())
        daemon.echo = lambda p, d=daemon, k=key: (names.setdefault(k, {t.name for t in threading.enumerate()}),
                                                   d.stop())
        daemon.run()
    assert "capture" not in names["recorded"]  # no hand-off for frames that cannot wedge
    assert "capture" in names["camera"]  # a camera call might: it runs where it cannot hold the loop


def test_frames_borrowed_from_the_camera_are_copied_for_the_recorder(fake_picamera2):
    fake_picamera2.WORLD.producer = static_rgb
    kept: List[np.ndarray] = []

    class Keeper:
        def add(self, image, index, payload, t_s):
            kept.append(image)  # kept past the next read, as the recorder's thread does

        def close(self):
            pass

    daemon = Daemon(picamera_cfg(retries=50), lambda cfg, sleep: open_source(cfg.source, cfg.camera, sleep=sleep,
                                                                   in_place=True),
                    lambda c: MemoryPublisher(), RecordingNotifier(), recorder=Keeper())
    daemon.echo = lambda p: len(kept) >= 3 and daemon.stop()
    assert daemon.run() == 0
    # the camera refills a released buffer (the fake writes 0xEE): the kept frames are copies, still the scene
    assert len(kept) >= 3 and all(np.mean(img == 0xEE) < 0.5 for img in kept)


def test_the_summary_says_what_the_pipeline_costs_and_how_often_it_tracks(static_clip):
    cfg = recorded_cfg(static_clip)  # unpaced: frames stamped as read, so the 0.25 s cadence would follow the load
    cfg = dataclasses.replace(cfg, detection=dataclasses.replace(cfg.detection, full_scan_interval_s=0.0))
    daemon = Daemon(cfg, opener, lambda c: MemoryPublisher(), RecordingNotifier())
    assert daemon.run() == 0
    s = daemon.summary()
    assert s.pipeline_cpu_ms > 0
    assert 50 < s.tracked_pct < 100  # 12 frames of a still scene: a full scan every eighth, tracked between
    assert "pipeline CPU" in s.line() and "% tracked" in s.line()


def test_freeze_gc_moves_start_up_objects_out_of_the_collector(static_clip):
    import gc

    daemon = Daemon(recorded_cfg(static_clip), opener, lambda c: MemoryPublisher(), RecordingNotifier(),
                    freeze_gc=True)
    try:
        assert daemon.run() == 0
        assert gc.get_freeze_count() > 1000
    finally:
        gc.unfreeze()
        gc.set_threshold(700, 10, 10)


def test_the_collector_paused_while_starting_runs_again_after_the_first_frame(static_clip):
    import gc

    daemon = Daemon(recorded_cfg(static_clip), opener, lambda c: MemoryPublisher(), RecordingNotifier(),
                    freeze_gc=True)
    enabled_after_first: List[bool] = []
    daemon.echo = lambda payload: enabled_after_first.append(gc.isenabled())
    gc.disable()  # as `rangebearing run` starts (cli.main)
    try:
        assert daemon.run() == 0
        assert gc.isenabled() and enabled_after_first[0] is False and all(enabled_after_first[1:])
    finally:
        gc.enable()
        gc.unfreeze()
        gc.set_threshold(700, 10, 10)


def test_run_never_leaves_the_collector_off(tmp_path):
    import gc

    from rangebearing.cli.main import main

    bad = tmp_path / "bad.yaml"
    bad.write_text("detection: {downscale: 9}\n", encoding="utf-8")
    assert gc.isenabled()
    assert main(["run", "--config", str(bad)]) != 0  # refused before any frame
    assert gc.isenabled()


def test_a_detector_defect_on_one_frame_is_skipped_counted_and_logged_with_its_traceback(static_clip, monkeypatch,
                                                                                         caplog):
    from rangebearing.core.pipeline import Pipeline

    real, calls = Pipeline.process, []

    def sometimes_broken(self, frame, t_s=None, search=None):
        calls.append(1)
        if len(calls) in (3, 7):
            raise IndexError("index 9 is out of bounds for axis 0 with size 9")
        return real(self, frame, t_s=t_s, search=search)

    monkeypatch.setattr(Pipeline, "process", sometimes_broken)
    pub = MemoryPublisher()
    daemon = Daemon(recorded_cfg(static_clip), opener, lambda cfg: pub, RecordingNotifier())
    with caplog.at_level("WARNING"):
        assert daemon.run() == 0
    assert daemon.stats.bad_frames == 2 and len(pub.payloads) == 10
    for p in pub.payloads:
        assert_matches_static_truth(p)
    faults = [r for r in caplog.records if "detector failed" in r.getMessage()]
    assert len(faults) == 2 and all(r.exc_info and r.exc_info[0] is IndexError for r in faults)
