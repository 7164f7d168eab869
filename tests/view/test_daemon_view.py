"""The daemon's loop with a view: frames offered only while someone watches, thresholds applied between frames."""

from __future__ import annotations

import dataclasses
import json
import threading
from pathlib import Path

from rangebearing.config import Config, SourceConfig
from rangebearing.daemon.loop import Daemon
from rangebearing.net.protocol import decode_reading
from rangebearing.net.publisher import MemoryPublisher
from rangebearing.sources.factory import open_source
from rangebearing.view import Thresholds, ViewHub
from tests.daemon.test_loop import RecordingNotifier


def opener(cfg, sleep):
    return open_source(cfg.source, cfg.camera, sleep=sleep)


def clip_cfg(path: Path, fps: float = 0.0, loop: bool = False) -> Config:
    src = dataclasses.replace(SourceConfig(), kind="recorded", path=str(path), fps=fps, loop=loop)
    return dataclasses.replace(Config(), source=src)


def test_no_viewer_nothing_offered(static_clip: Path) -> None:
    hub = ViewHub(Thresholds.of(Config().detection))
    hub.start()
    offered = []
    real = hub.offer
    hub.offer = lambda *a, **k: (offered.append(1), real(*a, **k))  # type: ignore[method-assign]
    pub = MemoryPublisher()
    assert Daemon(clip_cfg(static_clip), opener, lambda c: pub, RecordingNotifier(), view=hub).run() == 0
    hub.close()
    assert len(pub.payloads) == 12 and offered == [] and hub.encoded == 0


def test_thresholds_from_the_page_change_the_readings(static_clip: Path) -> None:
    cfg = clip_cfg(static_clip, fps=60.0, loop=True)
    hub = ViewHub(Thresholds.of(cfg.detection), max_fps=0)
    hub.start()
    pub = MemoryPublisher()
    daemon = Daemon(cfg, opener, lambda c: pub, RecordingNotifier(), view=hub)
    t = threading.Thread(target=daemon.run)
    t.start()
    try:
        with hub.viewer():
            snap = hub.wait(0, 10.0)
            assert snap is not None
            state = json.loads(snap.state)
            assert len(state["landmarks"]) == 2 and state["stats"]["frames"] >= 1
            assert set(state["stats"]["stage_ms"]) == {"wait", "process", "send"}
            hub.set_thresholds(dataclasses.replace(hub.thresholds, s_min=255))
            for _ in range(100):
                snap = hub.wait(snap.seq, 10.0)
                assert snap is not None
                if json.loads(snap.state)["thresholds"]["s_min"] == 255:
                    break
            n = len(pub.payloads)
            for _ in range(100):  # the hub's thread may still turn an offer sent before n into the next snapshot
                snap = hub.wait(snap.seq, 10.0)
                assert snap is not None
                if len(pub.payloads) > n:
                    break
        assert snap is not None and json.loads(snap.state)["landmarks"] == []
        assert daemon.cfg.detection.s_min == 255
        assert decode_reading(pub.payloads[-1]).landmarks == () and len(pub.payloads) > n  # published too
    finally:
        daemon.stop()
        t.join(10)
        hub.close()


def test_thresholds_the_pipeline_refuses_leave_the_loop_running(static_clip: Path, monkeypatch) -> None:
    from rangebearing.daemon import loop

    cfg = clip_cfg(static_clip)
    hub = ViewHub(Thresholds.of(cfg.detection))
    pub = MemoryPublisher()
    daemon = Daemon(cfg, opener, lambda c: pub, RecordingNotifier(), view=hub)

    def refuse(*a, **k):
        raise ValueError("no such pipeline")

    monkeypatch.setattr(loop, "Pipeline", refuse)
    hub.set_thresholds(dataclasses.replace(hub.thresholds, s_min=255))
    assert daemon.run() == 0
    assert len(pub.payloads) == 12 and all(len(decode_reading(p).landmarks) == 2 for p in pub.payloads)
    assert hub.thresholds.s_min == 90 and daemon.cfg.detection.s_min == 90  # the page shows what runs
