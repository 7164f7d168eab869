"""Picamera2Source against two independent fakes (tests/sources/camera_fakes.py): what any faithful one must give.

Parametrised over ``ours`` and ``alt`` (the clean-room fake): channel order, stride padding, the lores planes,
sensor time, released requests, timeouts without a leaked request, missing and busy cameras, bad controls,
closing. Tests only the clean-room fake can drive (API extras removed, the Pi 5 ISP, the leaked pipe) follow.
"""

from __future__ import annotations

import sys
import time
import types
from typing import Any, List

import numpy as np
import pytest

from rangebearing.config import SourceConfig
from rangebearing.core.yuv import yuv420_from_bgr
from rangebearing.errors import CameraError, CameraLibraryError, FrameError, SourceError
from rangebearing.sources import Picamera2Source
from tests.sources.camera_fakes import Alt, Camera

W, H = 40, 30  # 40 px: RGB888 rows of 120 bytes (the alt fake pads them to 128), lores Y 64 / chroma 32, H/2 odd


def cfg_for(cam: Camera, **kw: Any) -> SourceConfig:
    base = {"width_px": W, "height_px": H, "fps": 30.0, "timeout_s": cam.timeout_s, "retries": 3}
    base.update(kw)
    return SourceConfig(**base)  # type: ignore[arg-type]


def no_sleep(seconds: float) -> None:
    return None


def red(seq: int, h: int, w: int) -> np.ndarray:
    rgb = np.zeros((h, w, 3), np.uint8)
    rgb[..., 0] = 255
    return rgb


def noise(seq: int, h: int, w: int) -> np.ndarray:
    return np.random.default_rng(seq).integers(0, 256, (h, w, 3), np.uint8)


def open_source(cam: Camera, **kw: Any) -> Picamera2Source:
    in_place = bool(kw.pop("in_place", True))
    source = Picamera2Source(cfg_for(cam, **kw), sleep=no_sleep, in_place=in_place)
    source.open()
    return source


def test_rgb888_arrives_as_bgr_without_the_row_padding(camera: Camera) -> None:
    camera.scene(red, (W, H))
    source = open_source(camera)
    try:
        frame = source.read()
        assert frame is not None and frame.image.shape == (H, W, 3) and frame.image.dtype == np.uint8
        assert (frame.image[..., 2] == 255).all() and (frame.image[..., :2] == 0).all()
    finally:
        source.close()


def test_lores_planes_are_the_frame_in_yuv420(camera: Camera) -> None:
    camera.scene(noise, (W, H))
    source = open_source(camera)
    try:
        frame = source.read()
        assert frame is not None and frame.lores_yuv420 is not None
        yuv, want = frame.lores_yuv420, yuv420_from_bgr(frame.image)
        assert yuv.colour_space == "smpte170m"
        assert yuv.y.shape == (H, W) and yuv.u.shape == yuv.v.shape == (H // 2, W // 2)
        for got, ref in ((yuv.y, want.y), (yuv.u, want.u), (yuv.v, want.v)):  # no padding byte read, U not V
            assert np.abs(got.astype(int) - ref.astype(int)).max() <= 2
    finally:
        source.close()


def test_frames_are_stamped_with_the_sensor_time_in_order(camera: Camera) -> None:
    source = open_source(camera)
    try:
        frames = [source.read() for _ in range(5)]
        stamps = [f.t_mono_ns for f in frames if f is not None]
        indices = [f.index for f in frames if f is not None]
        assert len(stamps) == 5 and all(b > a for a, b in zip(stamps, stamps[1:]))
        assert stamps[-1] <= time.monotonic_ns()
        assert source.metadata["SensorTimestamp"] == stamps[-1]  # CLOCK_MONOTONIC already: used as is
        assert indices[0] == 0 and all(b > a for a, b in zip(indices, indices[1:]))
        assert indices[-1] == 4 + source.dropped  # frames the sensor made in between count as dropped
    finally:
        source.close()


def test_every_request_is_released(camera: Camera) -> None:
    source = open_source(camera)
    for _ in range(10):  # more than the 4 buffers: a leak would stall the camera
        assert source.read() is not None
        assert camera.held() == 1  # only the frame just returned (in place)
    source.close()
    assert camera.held() == 0 and camera.open_cameras() == set()


def test_frames_to_keep_are_copies(camera: Camera) -> None:
    camera.scene(lambda seq, h, w: np.full((h, w, 3), seq % 200 + 20, np.uint8), (W, H))
    source = open_source(camera, in_place=False)
    try:
        first = source.read()
        assert first is not None and camera.held() == 0  # copied out, released at once
        kept = first.image.copy()
        for _ in range(6):  # the camera reuses every buffer meanwhile
            source.read()
        assert np.array_equal(first.image, kept)
    finally:
        source.close()


def test_a_timeout_is_survived_without_leaking_a_request(camera: Camera) -> None:
    source = open_source(camera)
    try:
        assert source.read() is not None
        camera.stall(True)
        with pytest.raises(FrameError, match="no frame within"):
            source.read()
        camera.stall(False)
        for _ in range(6):  # the timed-out job was flushed: it neither eats frames nor holds a buffer
            assert source.read() is not None
        assert camera.held() == 1
    finally:
        source.close()


def test_consecutive_timeouts_become_a_camera_error(camera: Camera) -> None:
    source = open_source(camera, retries=2)
    try:
        source.read()
        camera.stall(True)
        with pytest.raises(FrameError) as first:
            source.read()
        assert not isinstance(first.value, CameraError)
        with pytest.raises(CameraError, match="2 times in a row"):
            source.read()
    finally:
        source.close()


def test_a_missing_camera_is_a_camera_error_after_the_retries(camera: Camera) -> None:
    camera.no_cameras()
    sleeps: List[float] = []
    with pytest.raises(CameraError, match=r"no camera 0 \(0 found\)"):
        Picamera2Source(cfg_for(camera, retries=2), sleep=sleeps.append, backoff_s=0.5).open()
    assert sleeps == [0.5, 1.0]


def test_a_busy_camera_is_a_camera_error(camera: Camera) -> None:
    holder = camera.module.Picamera2(0)
    try:
        with pytest.raises(CameraError, match="busy"):
            Picamera2Source(cfg_for(camera, retries=1), sleep=no_sleep).open()
    finally:
        holder.close()
    source = open_source(camera)  # free again
    source.close()


def test_a_bad_control_fails_open_and_frees_the_camera(camera: Camera) -> None:
    with pytest.raises(CameraError, match="NoSuchControl"):
        open_source(camera, controls=(("NoSuchControl", 1),))
    assert camera.open_cameras() == set()


def test_close_is_idempotent_and_reading_after_it_is_an_error(camera: Camera) -> None:
    source = open_source(camera)
    source.read()
    source.close()
    source.close()
    assert camera.open_cameras() == set()
    with pytest.raises(SourceError, match="not open"):
        source.read()


def test_the_configuration_asked_for(camera: Camera) -> None:
    source = open_source(camera, fps=20.0, buffer_count=3, controls=(("ExposureTime", 24000),))
    try:
        granted = camera.granted()
        assert granted["main"]["format"] == "RGB888" and tuple(granted["main"]["size"]) == (W, H)
        assert granted["lores"]["format"] == "YUV420" and tuple(granted["lores"]["size"]) == (W, H)
        assert granted["buffer_count"] == 3
        assert granted["controls"]["FrameDurationLimits"] == (50000, 50000)
        assert granted["controls"]["ExposureTime"] == 24000
        space = granted["colour_space"]
        assert getattr(space, "name", str(space)) == "SMPTE170M"  # asked, or picamera2's default below 720p
    finally:
        source.close()


# ---------------------------------------------------------------- the clean-room fake only
def test_a_missing_camera_is_constructed_only_on_the_last_attempt(alt_picamera2: Any,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    module, rig = alt_picamera2
    rig.RIG.cameras = []
    real = module.Picamera2.__init__
    calls: List[int] = []

    def counted(self: Any, camera_num: int = 0, **kw: Any) -> None:  # the real one leaks a pipe here
        calls.append(camera_num)
        real(self, camera_num, **kw)

    monkeypatch.setattr(module.Picamera2, "__init__", counted)
    with pytest.raises(CameraError, match=r"no camera 0 \(0 found\)"):
        Picamera2Source(SourceConfig(retries=3), sleep=no_sleep).open()
    assert calls == [0]  # 4 attempts: 3 asked global_camera_info() first


def test_a_camera_count_that_is_wrong_does_not_hide_the_camera(alt_picamera2: Any,
                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    module, _ = alt_picamera2
    monkeypatch.setattr(module.Picamera2, "global_camera_info", staticmethod(lambda: []))
    source = Picamera2Source(SourceConfig(width_px=W, height_px=H, timeout_s=4.0, retries=1), sleep=no_sleep)
    source.open()  # the constructor has the last word
    try:
        assert source.read() is not None
    finally:
        source.close()


def test_a_create_video_configuration_with_only_the_core_keywords(alt_picamera2: Any,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    module, rig = alt_picamera2
    libcamera = types.ModuleType("libcamera")  # a libcamera is there, but picamera2 takes no colour space
    libcamera.ColorSpace = module.ColorSpace  # type: ignore[attr-defined]
    libcamera.Transform = lambda hflip=False, vflip=False: (hflip, vflip)  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "libcamera", libcamera)
    real = module.Picamera2.create_video_configuration

    def core(self: Any, main: Any = None, lores: Any = None, buffer_count: int = 6, controls: Any = None,
             queue: bool = True) -> dict:
        return real(self, main=main or {}, lores=lores, buffer_count=buffer_count, controls=controls or {},
                    queue=queue)

    monkeypatch.setattr(module.Picamera2, "create_video_configuration", core)
    rig.RIG.scene = lambda seq: noise(seq, H, W)
    source = open_source(Alt(module, rig))
    try:
        frame = source.read()
        assert frame is not None and frame.lores_yuv420 is not None
        want = yuv420_from_bgr(frame.image)
        assert np.abs(frame.lores_yuv420.v.astype(int) - want.v.astype(int)).max() <= 2
    finally:
        source.close()
    with pytest.raises(CameraError, match="hflip/vflip"):
        Picamera2Source(SourceConfig(vflip=True, retries=0), sleep=no_sleep).open()
    assert rig.RIG.acquired == set()


@pytest.mark.parametrize("missing", [
    ("global_camera_info",), ("camera_configuration",), ("camera_configuration", "stream_configuration"),
    ("MappedArray",), ("cancel_all_and_flush",), ("colour_space",), ("platform", "sensor_modes",
                                                                    "align_configuration", "camera_properties"),
    ("global_camera_info", "camera_configuration", "stream_configuration", "MappedArray",
     "cancel_all_and_flush", "colour_space"),
])
def test_a_less_complete_picamera2_still_gives_frames_and_lores(alt_picamera2: Any, missing: tuple) -> None:
    module, rig = alt_picamera2
    rig.configure(frame_duration_us=5000, missing=set(missing), scene=lambda seq: noise(seq, H, W))
    for name in set(missing) - {"colour_space"}:  # colour_space: left out of camera_configuration()
        assert not hasattr(module if name == "MappedArray" else module.Picamera2, name)
    cam = Alt(module, rig)
    source = open_source(cam)
    try:
        for _ in range(3):
            frame = source.read()
            assert frame is not None and frame.image.shape == (H, W, 3)
            assert frame.lores_yuv420 is not None
            want = yuv420_from_bgr(frame.image)
            assert np.abs(frame.lores_yuv420.v.astype(int) - want.v.astype(int)).max() <= 2
        assert rig.held() == 1
    finally:
        source.close()
    assert rig.RIG.acquired == set()


def test_without_capture_request_capture_array_gives_the_main_image(alt_picamera2: Any,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    module, rig = alt_picamera2
    rig.RIG.scene = lambda seq: red(seq, H, W)
    monkeypatch.delattr(module.Picamera2, "capture_request")
    source = open_source(Alt(module, rig))
    try:
        frame = source.read()
        assert frame is not None and frame.lores_yuv420 is None  # no request: no lores of the same frame
        assert (frame.image[..., 2] == 255).all() and (frame.image[..., :2] == 0).all()
        assert frame.t_mono_ns <= time.monotonic_ns()
    finally:
        source.close()


@pytest.mark.parametrize("platform", ["vc4", "pisp"])
@pytest.mark.parametrize("size", [(40, 30), (64, 48), (650, 486)])  # PiSP pads 650 px RGB rows to 1984 bytes
def test_pi4_and_pi5_strides(alt_picamera2: Any, platform: str, size: tuple) -> None:
    _, rig = alt_picamera2
    w, h = size
    scenes = [noise(seq, h, w) for seq in range(2)]
    rig.configure(frame_duration_us=20000, platform=platform, scene=scenes)
    source = Picamera2Source(SourceConfig(width_px=w, height_px=h, timeout_s=2.0), sleep=no_sleep, in_place=True)
    source.open()
    try:
        frame = source.read()
        assert frame is not None and frame.image.shape == (h, w, 3) and frame.lores_yuv420 is not None
        want = yuv420_from_bgr(frame.image)
        assert np.abs(frame.lores_yuv420.y.astype(int) - want.y.astype(int)).max() <= 2
        assert np.abs(frame.lores_yuv420.u.astype(int) - want.u.astype(int)).max() <= 2
        stride = rig.RIG.instances[0].camera_configuration()["lores"]["stride"]
        assert stride % (64 if platform == "vc4" else 128) == 0 and stride >= w  # chroma rows: stride / 2
    finally:
        source.close()


def test_flips_without_libcamera_are_a_clear_error(alt_picamera2: Any) -> None:
    _, rig = alt_picamera2
    with pytest.raises(CameraError, match="hflip/vflip need libcamera"):
        Picamera2Source(SourceConfig(hflip=True, retries=0), sleep=no_sleep).open()
    assert rig.RIG.acquired == set()


def test_no_picamera2_is_one_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "picamera2", None)
    with pytest.raises(CameraLibraryError, match=r"cannot import picamera2.*--system-site-packages"):
        Picamera2Source(SourceConfig()).open()



@pytest.mark.parametrize("main_format", ["RGB888", "BGR888", "XBGR8888", "XRGB8888"])
@pytest.mark.parametrize("lores_format", ["YUV420", "YVU420"])
def test_formats_libcamera_may_grant_instead(alt_picamera2: Any, main_format: str, lores_format: str) -> None:
    module, rig = alt_picamera2
    rig.configure(frame_duration_us=5000, scene=lambda seq: noise(seq, H, W),
                  adjust={"main": {"format": main_format}, "lores": {"format": lores_format}})
    source = open_source(Alt(module, rig))
    try:
        frame = source.read()
        assert rig.RIG.instances[0].camera_configuration()["main"]["format"] == main_format
        assert frame is not None and frame.image.shape == (H, W, 3) and frame.lores_yuv420 is not None
        want = yuv420_from_bgr(frame.image)  # BGR in the right order: its YUV matches the camera's
        for got, ref in ((frame.lores_yuv420.y, want.y), (frame.lores_yuv420.u, want.u),
                         (frame.lores_yuv420.v, want.v)):
            assert np.abs(got.astype(int) - ref.astype(int)).max() <= 2
    finally:
        source.close()


def test_the_camera_reopens_after_close(camera: Camera) -> None:
    camera.scene(red, (W, H))
    for _ in range(2):  # the daemon reopens a camera that stopped delivering
        source = open_source(camera)
        try:
            frame = source.read()
            assert frame is not None and (frame.image[..., 2] == 255).all()
        finally:
            source.close()
        assert camera.open_cameras() == set() and camera.held() == 0


def test_frames_mapped_read_only_go_through_the_pipeline_untouched(alt_picamera2: Any) -> None:
    """MappedArray(write=False) maps the buffer PROT_READ on the real library: nothing downstream may write it."""
    from rangebearing.core.params import PipelineParams
    from rangebearing.core.pipeline import Pipeline

    module, rig = alt_picamera2
    rig.RIG.scene = lambda seq: noise(seq, 480, 640)
    source = open_source(Alt(module, rig), width_px=640, height_px=480)
    try:
        pipe = Pipeline(PipelineParams(), track=True)
        for _ in range(3):
            frame = source.read()
            assert frame is not None and not frame.image.flags.writeable
            lores = frame.lores_yuv420
            assert lores is not None and not lores.y.flags.writeable
            before = frame.image.copy()
            pipe.process(frame.image, t_s=frame.t_mono_ns / 1e9, search=lores)
            assert (frame.image == before).all()
    finally:
        source.close()
