"""daemon.scan_after_send: the periodic full scan runs after its frame's readings are sent; nothing is lost."""

from __future__ import annotations

import dataclasses

from rangebearing.daemon.loop import Daemon
from rangebearing.net.protocol import decode_reading
from rangebearing.net.publisher import MemoryPublisher
from tests.daemon.test_loop import RecordingNotifier, opener, recorded_cfg


def _run(clip, scan_after_send: bool):
    cfg = recorded_cfg(clip)
    det = dataclasses.replace(cfg.detection, full_scan_every=3, full_scan_interval_s=0.0)  # every 3rd frame
    cfg = dataclasses.replace(cfg, detection=det,
                              daemon=dataclasses.replace(cfg.daemon, scan_after_send=scan_after_send))
    pub, note = MemoryPublisher(), RecordingNotifier(watchdog_s=1e-6)
    daemon = Daemon(cfg, opener, lambda c: pub, note)
    assert daemon.run() == 0
    return daemon, [decode_reading(p) for p in pub.payloads], note


def _seen(reading):
    return [(lm.range_m, lm.bearing_rad, lm.track_id) for lm in reading.landmarks]


def test_every_frame_is_sent_in_order_with_the_same_landmarks_and_ids(static_clip):
    on, sent_on, note = _run(static_clip, True)
    off, sent_off, _ = _run(static_clip, False)
    assert [r.seq for r in sent_on] == [r.seq for r in sent_off] == list(range(12))
    assert note.calls[0] == "READY" and note.calls[-1] == "STOPPING"
    scanned_later = [i for i in range(12) if i % 3 == 0 and i > 0]  # frames 3, 6, 9: their scans ran after the send
    for i, (a, b) in enumerate(zip(sent_on, sent_off)):
        if i in scanned_later:  # the tracked readings went out: the same landmarks and ids, a scan's worth apart
            assert [lm.track_id for lm in a.landmarks] == [lm.track_id for lm in b.landmarks]
            for x, y in zip(a.landmarks, b.landmarks):
                assert abs(x.range_m - y.range_m) < 0.003 * y.range_m and abs(x.bearing_rad - y.bearing_rad) < 6e-4
        else:  # every other frame reads bit for bit as without the switch
            assert _seen(a) == _seen(b)
    s_on, s_off = on.summary(), off.summary()
    assert "scan" in s_on.stage_ms and "scan" not in s_off.stage_ms
    assert s_on.tracked_pct > s_off.tracked_pct  # the scans' frames were sent tracked
    assert s_on.bad_frames == s_off.bad_frames == 0


def test_auto_scans_after_the_send_at_latency_bound_rates_only(tmp_path):
    from rangebearing.config import Config, load_config
    from rangebearing.daemon.loop import scans_after_send
    from rangebearing.errors import ConfigError

    assert Config().daemon.scan_after_send == "auto"
    at = {fps: scans_after_send(dataclasses.replace(Config(), source=dataclasses.replace(Config().source, fps=fps)))
          for fps in (0.0, 30.0, 59.0, 60.0, 90.0)}
    assert at == {0.0: False, 30.0: False, 59.0: False, 60.0: True, 90.0: True}
    forced = dataclasses.replace(Config(), daemon=dataclasses.replace(Config().daemon, scan_after_send=False),
                                 source=dataclasses.replace(Config().source, fps=90.0))
    assert scans_after_send(forced) is False
    path = tmp_path / "c.yaml"
    for text, value in (("auto", "auto"), ("true", True), ("false", False)):
        path.write_text(f"daemon: {{scan_after_send: {text}}}\n")
        assert load_config(path).daemon.scan_after_send == value
    path.write_text("daemon: {scan_after_send: sometimes}\n")
    try:
        load_config(path)
    except ConfigError as exc:
        assert "daemon.scan_after_send: expected true, false or auto" in str(exc)
    else:
        raise AssertionError("'sometimes' was accepted")
