"""Picamera2Source against a third stand-in (tests/fakes/picamera2_quirks): each documented corner on its own.

Every quirk must give frames of the right colours (or a counted skip: FrameError), timeouts as FrameError then
CameraError, and a close that returns: never another exception out of ``read()``.
"""

from __future__ import annotations

import importlib.util
import logging
import os
import sys
from pathlib import Path
from types import ModuleType
from typing import Iterator

import numpy as np
import pytest

from rangebearing.config import SourceConfig
from rangebearing.errors import CameraError, FrameError
from rangebearing.sources.camera_capture import sensor_fields
from rangebearing.sources.picamera2_source import Picamera2Source
from tests.conftest import FAKES

QUIRKS_DIR = FAKES / "picamera2_quirks"
TIMEOUT_S = 60.0


@pytest.fixture
def quirky(monkeypatch: pytest.MonkeyPatch) -> Iterator[ModuleType]:
    """The quirks fake as ``picamera2`` (and no importable libcamera) for one test."""
    init = QUIRKS_DIR / "__init__.py"
    spec = importlib.util.spec_from_file_location("picamera2", init, submodule_search_locations=[str(QUIRKS_DIR)])
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "picamera2", module)
    monkeypatch.setitem(sys.modules, "libcamera", None)  # import libcamera raises ImportError
    spec.loader.exec_module(module)
    module.reset()
    yield module
    module.reset()


def source(in_place: bool = True, **cfg: object) -> Picamera2Source:
    base = {"timeout_s": 0.05, "retries": 3, **cfg}
    return Picamera2Source(SourceConfig(**base), in_place=in_place, stop_timeout_s=5.0)  # type: ignore[arg-type]


def true_bgr(sequence: int) -> list:
    """The quirks fake's default scene at ``sequence``, as B, G, R."""
    return [255 - (sequence * 7) % 256, 128, (sequence * 7) % 256]


# quirk -> does lores survive it
FRAME_QUIRKS = {
    "no_wait": True, "builtin_timeout": True, "no_metadata": True, "metadata_none": True, "lores_unpadded": True,
    "lores_smaller": False, "map_fails": True, "xbgr": True, "release_fails": True, "close_fails": True,
    "float_timestamp": True, "no_frame_duration": True, "tuple_config": True, "flush_fails": True,
    "flat_main": True, "flat_bytes": True, "yuv420_main": True, "nv12_main": True, "yuyv_main": True,
    "rgb16_main": True, "mjpeg_main": True, "mjpeg_bytes": True, "config_attr_only": True, "preview_only": True,
    "no_create": True, "config_objects": True, "few_keywords": True,
}
# quirk -> how far a pixel may be from the scene's (a main stream through Y'CbCr or JPEG is not exact)
TOLERANCE = {"yuv420_main": 2, "nv12_main": 2, "yuyv_main": 2, "mjpeg_main": 4, "mjpeg_bytes": 4}


@pytest.mark.parametrize("in_place", [True, False])
@pytest.mark.parametrize("quirk", sorted(FRAME_QUIRKS))
def test_every_quirk_gives_true_frames_then_timeouts_then_a_clean_close(quirky: ModuleType, quirk: str,
                                                                        in_place: bool) -> None:
    quirky.QUIRKS.add(quirk)
    src = source(in_place)
    src.open()
    for sequence in range(1, 5):
        frame = src.read()
        assert frame is not None and frame.image.shape == (480, 640, 3)
        error = np.abs(frame.image[10, 10].astype(int) - true_bgr(sequence)).max()
        assert error <= TOLERANCE.get(quirk, 0), (frame.image[10, 10], true_bgr(sequence))
        if FRAME_QUIRKS[quirk]:
            assert frame.lores_yuv420 is not None and frame.lores_yuv420.u.shape == (240, 320)
            u = int(frame.lores_yuv420.u[5, 5])
            assert (u > 128) == (true_bgr(sequence)[0] > true_bgr(sequence)[2])  # blue over red: U above 128
        else:
            assert frame.lores_yuv420 is None
    quirky.STALLED.set()
    with pytest.raises(FrameError):
        src.read()
    with pytest.raises(FrameError):
        src.read()
    with pytest.raises(CameraError, match="3 times in a row"):
        src.read()
    src.close()
    assert not quirky.OPEN and not quirky.HELD  # released and closed, whatever stop()/close() raised


def test_a_capture_that_returns_nothing_is_one_skipped_frame(quirky: ModuleType) -> None:
    quirky.QUIRKS.add("none_request")
    src = source()
    src.open()
    got = []
    for _ in range(5):
        try:
            got.append(src.read().image[10, 10].tolist())  # type: ignore[union-attr]
        except FrameError as exc:
            assert "returned no request" in str(exc)
            got.append(None)
    src.close()
    assert got == [true_bgr(1), true_bgr(2), None, true_bgr(4), true_bgr(5)]


def test_main_stream_that_cannot_be_read_is_a_skipped_frame_not_a_crash(quirky: ModuleType) -> None:
    quirky.QUIRKS.update({"map_fails", "make_array_fails", "make_buffer_fails"})  # frame 1: nothing reads it
    src = source()
    src.open()
    with pytest.raises(FrameError, match="unusable request"):
        src.read()
    assert src.read().image[10, 10].tolist() == true_bgr(2)  # type: ignore[union-attr]
    src.close()
    assert not quirky.HELD  # the failed request was given back


def test_a_main_stream_make_array_cannot_shape_is_read_from_its_bytes(quirky: ModuleType) -> None:
    quirky.QUIRKS.update({"map_fails", "make_array_fails"})  # frame 1: make_array fails, make_buffer does not
    src = source()
    src.open()
    for sequence in (1, 2):
        assert src.read().image[10, 10].tolist() == true_bgr(sequence)  # type: ignore[union-attr]
    src.close()
    assert not quirky.HELD


@pytest.mark.parametrize("quirk", ["yuv420_main", "nv12_main"])
def test_a_yuv420_main_stream_without_lores_is_searched_on_its_own_planes(quirky: ModuleType, quirk: str) -> None:
    quirky.QUIRKS.add(quirk)
    src = source(lores=False)
    src.open()
    frame = src.read()
    assert frame is not None and frame.lores_yuv420 is not None
    assert frame.lores_yuv420.y.shape == (480, 640) and frame.lores_yuv420.u.shape == (240, 320)
    assert int(frame.lores_yuv420.u[5, 5]) > 128  # the first frame is blue over red
    src.close()


@pytest.mark.parametrize("quirk", ["rgb16_main", "yuyv_main", "mjpeg_bytes"])
def test_a_main_stream_that_does_not_fit_its_format_is_a_skipped_frame(quirky: ModuleType, quirk: str,
                                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    quirky.QUIRKS.add(quirk)
    src = source()
    src.open()
    real = quirky.CompletedRequest._shaped
    monkeypatch.setattr(quirky.CompletedRequest, "_shaped", lambda self, name: real(self, name)[:7])
    with pytest.raises(FrameError):
        src.read()
    monkeypatch.setattr(quirky.CompletedRequest, "_shaped", real)
    assert src.read() is not None
    src.close()
    assert not quirky.HELD


@pytest.mark.parametrize("quirk", ["few_keywords", "no_create", "config_objects"])
def test_the_frame_rate_reaches_a_camera_whatever_makes_its_configuration(quirky: ModuleType, quirk: str) -> None:
    quirky.QUIRKS.add(quirk)
    src = source(fps=50.0)
    src.open()
    assert quirky.INSTANCES[-1].frame_us == 20000  # FrameDurationLimits in the dict configure() was given
    assert src.read() is not None
    src.close()


def test_a_size_the_camera_aligns_is_read_as_granted(quirky: ModuleType) -> None:
    quirky.QUIRKS.add("aligned")
    src = source(width_px=650, height_px=486)  # VC4 aligns RGB888 widths to 32 px, YUV420 to 64: both 640
    src.open()
    frame = src.read()
    assert frame is not None and frame.image.shape == (486, 640, 3)
    assert frame.image[10, 10].tolist() == true_bgr(1)
    assert frame.lores_yuv420 is not None and frame.lores_yuv420.u.shape == (243, 320)
    src.close()


def test_a_library_quirk_is_said_once_not_every_frame(quirky: ModuleType, caplog: pytest.LogCaptureFixture) -> None:
    quirky.QUIRKS.update({"release_fails", "no_wait"})
    src = source()
    src.open()
    with caplog.at_level(logging.DEBUG, logger="rangebearing"):
        for _ in range(6):
            src.read()
    src.close()
    warnings = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert sum("release failed" in w for w in warnings) == 1, warnings
    assert sum("takes no wait=" in w for w in warnings) == 1, warnings


def test_a_job_handed_back_for_the_capture_is_waited_for(quirky: ModuleType, monkeypatch: pytest.MonkeyPatch) -> None:
    real = quirky.Picamera2.capture_request
    monkeypatch.setattr(quirky.Picamera2, "capture_request", lambda self, wait=None: real(self, wait=False))
    src = source()
    src.open()
    assert src.read().image[10, 10].tolist() == true_bgr(1)  # type: ignore[union-attr]
    src.close()


@pytest.mark.parametrize("quirk, says", [("open_fails", "failed to open: OSError"),
                                         ("start_fails", "cannot configure and start: bad control value")])
def test_an_open_that_fails_in_the_library_s_own_way_is_a_camera_error_then_retried(
        quirky: ModuleType, quirk: str, says: str) -> None:
    quirky.QUIRKS.add(quirk)
    waits: list = []
    src = Picamera2Source(SourceConfig(timeout_s=0.05, retries=3), in_place=True, sleep=waits.append,
                          stop_timeout_s=5.0)
    if quirk == "open_fails":  # retried inside open(): the second attempt finds the camera
        src.open()
        assert len(waits) == 1
    else:  # configured but not started: closed again, and the daemon's next open() works
        with pytest.raises(CameraError, match=says):
            src.open()
        assert not quirky.OPEN
        src.open()
    assert src.read().image[10, 10].tolist() == true_bgr(1)  # type: ignore[union-attr]
    src.close()


def test_an_unexpected_library_error_is_a_camera_error_the_daemon_retries(quirky: ModuleType,
                                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    def broken(self: object, wait: object = None) -> None:
        raise OSError(5, "Input/output error")

    monkeypatch.setattr(quirky.Picamera2, "capture_request", broken)
    src = source()
    src.open()
    with pytest.raises(CameraError, match=r"capture failed.*Input/output error"):
        src.read()
    src.close()


@pytest.mark.parametrize("meta, want", [
    ({"SensorTimestamp": 12, "FrameDuration": 33333}, (12, 33333.0)),
    ({"SensorTimestamp": 12.7}, (12, None)),
    ({"SensorTimestamp": "soon", "FrameDuration": "x"}, (None, None)),
    ({"SensorTimestamp": None, "FrameDuration": 0}, (None, None)),
    ({"SensorTimestamp": float("inf"), "FrameDuration": float("nan")}, (None, None)),
    ({}, (None, None)),
])
def test_sensor_fields_take_only_numbers(meta: dict, want: tuple) -> None:
    assert sensor_fields(meta) == want


@pytest.mark.parametrize("quirks", [
    "no_wait,no_metadata,release_fails,flush_fails,xbgr,lores_unpadded,close_fails",
    "yuv420_main,config_objects,few_keywords,float_timestamp",  # the main stream converted, stamps of its own
])
def test_the_daemon_runs_on_the_quirkiest_camera(tmp_path: Path, quirks: str) -> None:
    from rangebearing.net.client import Subscriber
    from rangebearing.synth import render
    from tests.conftest import STATIC_SCENE
    from tests.sources.test_picamera2_daemon import start, three_true_readings_then_stop

    np.save(tmp_path / "scene.npy", np.ascontiguousarray(render(STATIC_SCENE, np.random.default_rng(3))[:, :, ::-1]))
    site = tmp_path / "site" / "picamera2"
    site.mkdir(parents=True)
    (site / "__init__.py").write_text(f"exec(compile(open({str(QUIRKS_DIR / '__init__.py')!r}).read(), "
                                      f"{str(QUIRKS_DIR / '__init__.py')!r}, 'exec'))\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path / "site"), os.environ.get("PYTHONPATH", "")]),
           "PICAMERA2_QUIRKS": quirks,
           "PICAMERA2_SCENE": str(tmp_path / "scene.npy")}
    with Subscriber(port=0, timeout_s=TIMEOUT_S) as sub:
        proc = start(tmp_path, f"""
source: {{kind: picamera2, fps: 30, timeout_s: 1.0}}
publish: {{robot_id: pi, unicast: ["127.0.0.1:{sub.port}"]}}
""", env)
        code, stderr = three_true_readings_then_stop(proc, sub)
    assert code == 0, stderr
    assert "Traceback" not in stderr, stderr
    if "release_fails" in quirks:
        assert 1 <= stderr.count("release failed") <= 2, stderr  # once a camera opened (a reopen may say it again)


@pytest.mark.parametrize("quirk", ["yuv420_main", "yuyv_main", "rgb16_main", "mjpeg_main"])
def test_landmarks_in_a_main_stream_granted_in_another_format_are_found_where_rgb888_finds_them(
        quirky: ModuleType, quirk: str) -> None:
    from rangebearing.config import load_config
    from rangebearing.core.pipeline import Pipeline
    from rangebearing.synth import render
    from tests.conftest import STATIC_SCENE

    rgb = np.ascontiguousarray(render(STATIC_SCENE, np.random.default_rng(3))[:, :, ::-1])
    quirky.SCENE = lambda sequence, height, width: rgb
    found = {}
    for granted in ("", quirk):
        quirky.QUIRKS.clear()
        quirky.QUIRKS.update({granted} - {""})
        src = source(lores=False)
        src.open()
        frame = src.read()
        assert frame is not None
        result = Pipeline(load_config(None).pipeline).process(frame.image, search=frame.lores_yuv420)
        found[granted] = [(lm.range_m, lm.bearing_rad) for lm in result.landmarks]
        src.close()
    truth = sorted((lm.range_m, lm.bearing_rad) for lm in STATIC_SCENE.landmarks)
    assert len(found[""]) == len(found[quirk]) == len(truth)
    for (r0, b0), (r1, b1) in zip(sorted(found[""]), sorted(found[quirk])):
        assert abs(r1 - r0) <= 0.01 * r0 and abs(b1 - b0) <= 0.002


def test_sensor_stamps_on_a_clock_of_their_own_keep_their_spacing_shifted_to_the_arrivals(
        quirky: ModuleType) -> None:
    """The quirks fake stamps frames 1 s + n frame periods "after boot": no clock of ours (a counter)."""
    arrivals = iter(range(50_000_000_000, 60_000_000_000, 40_000_000))  # a frame arrives every 40 ms
    src = Picamera2Source(SourceConfig(timeout_s=0.05, retries=3), in_place=True, stop_timeout_s=5.0,
                          clock=lambda: next(arrivals))
    src.open()
    stamps = [src.read().t_mono_ns for _ in range(4)]  # type: ignore[union-attr]
    src.close()
    assert stamps[0] == 50_000_000_000  # the first is stamped when it arrived, not 1 s after boot
    assert [b - a for a, b in zip(stamps, stamps[1:])] == [33_333_000] * 3  # the camera's own spacing kept
    assert src.dropped == 0


def test_sensor_stamps_on_no_clock_of_ours_never_lie_after_the_arrival_and_follow_a_jump() -> None:
    from rangebearing.sources.sensor_time import SensorClock

    clock = SensorClock(boot_offset_ns=0)
    assert clock.to_monotonic_ns(9_000_000_000, 10_000_000_000) == 9_000_000_000  # monotonic: as it is
    assert clock.to_monotonic_ns(100, 20_000_000_000) == 20_000_000_000  # a counter: shifted to its arrival
    assert clock.to_monotonic_ns(100 + 33_000_000, 20_040_000_000) == 20_033_000_000  # its spacing kept
    assert clock.to_monotonic_ns(100 + 66_000_000, 20_050_000_000) == 20_050_000_000  # never after arrival
    hour = 3_600_000_000_000
    assert clock.to_monotonic_ns(hour, 20_100_000_000) == 20_100_000_000  # a jump: the shift learnt again
    assert clock.to_monotonic_ns(hour + 33_000_000, 20_140_000_000) == 20_133_000_000
