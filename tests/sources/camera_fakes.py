"""Two independent picamera2 fakes behind one small driver, so source tests run against both.

``ours`` is tests/fakes/picamera2 (lockstep: a frame is made when it is asked for, with its libcamera fake);
``alt`` is tests/fakes/picamera2_alt, written clean-room from the real library: a free-running camera thread,
jobs and timeouts as the real dispatch_functions, buffers recycled on release, rows padded to the ISP's
alignment, and no libcamera module at all (a stand-in picamera2 need not bring one).
"""

from __future__ import annotations

import sys
from pathlib import Path
from types import ModuleType
from typing import Callable, Iterator

import numpy as np
import pytest

from tests.conftest import FAKES, _install_fake

ALT = FAKES / "picamera2_alt"
Producer = Callable[[int, int, int], np.ndarray]  # (sequence, height, width) -> RGB


def _fake_modules() -> list[str]:
    return [m for m in sys.modules if m in ("picamera2", "libcamera", "picamera2_alt_rig")
            or m.startswith("picamera2.")]


class Camera:
    """What a test does to the camera behind the library: the scene, a stall, what is held, who is open."""

    name = ""
    timeout_s = 1.0  # the source's capture timeout for this fake

    def __init__(self, module: ModuleType) -> None:
        self.module = module

    def scene(self, producer: Producer, size: tuple[int, int]) -> None:
        raise NotImplementedError

    def stall(self, stalled: bool) -> None:
        raise NotImplementedError

    def held(self) -> int:
        raise NotImplementedError

    def open_cameras(self) -> set:
        raise NotImplementedError

    def no_cameras(self) -> None:
        raise NotImplementedError

    def granted(self) -> dict:
        """The first camera's configuration as the library holds it."""
        raise NotImplementedError


class Ours(Camera):
    name = "ours"
    timeout_s = 0.05  # lockstep: a frame is there at once unless stalled

    def scene(self, producer: Producer, size: tuple[int, int]) -> None:
        self.module.WORLD.producer = producer

    def stall(self, stalled: bool) -> None:
        self.module.WORLD.set_stalled(stalled)

    def held(self) -> int:
        return len(self.module.WORLD.outstanding)

    def open_cameras(self) -> set:
        return set(self.module.WORLD.open_cameras)

    def no_cameras(self) -> None:
        self.module.WORLD.num_cameras = 0

    def granted(self) -> dict:
        return self.module.WORLD.instances[0].camera_config


class Alt(Camera):
    name = "alt"
    timeout_s = 4.0  # free-running at 200 fps: generous for a loaded machine

    def __init__(self, module: ModuleType, rig: ModuleType) -> None:
        super().__init__(module)
        self.rig = rig

    def scene(self, producer: Producer, size: tuple[int, int]) -> None:
        w, h = size
        self.rig.RIG.scene = lambda seq: producer(seq, h, w)

    def stall(self, stalled: bool) -> None:
        rig = self.rig.RIG
        with rig.lock:
            rig.stop_after = rig.frames_delivered if stalled else None
        if stalled:  # a frame in flight lands, then is dropped: the next capture finds the camera silent
            assert rig.wait_ticks(3)
            for cam in rig.instances:
                with cam.lock:
                    while cam.completed_requests:
                        cam.completed_requests.pop(0).release()

    def held(self) -> int:
        return self.rig.held()

    def open_cameras(self) -> set:
        return set(self.rig.RIG.acquired)

    def no_cameras(self) -> None:
        self.rig.RIG.cameras = []

    def granted(self) -> dict:
        return self.rig.RIG.instances[0].camera_configuration()


@pytest.fixture
def alt_picamera2(monkeypatch: pytest.MonkeyPatch) -> Iterator[tuple[ModuleType, ModuleType]]:
    """The clean-room fake as ``picamera2`` (and its rig), with NO libcamera importable; undone after."""
    for name in _fake_modules():
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "libcamera", None)  # import libcamera -> ImportError
    monkeypatch.syspath_prepend(str(ALT))
    import picamera2
    import picamera2_alt_rig

    assert Path(picamera2.__file__).parent.parent == ALT
    picamera2_alt_rig.configure(frame_duration_us=5000)
    try:
        yield picamera2, picamera2_alt_rig
    finally:
        picamera2_alt_rig.shutdown()  # every camera of this test closed, its thread ended
        picamera2_alt_rig.configure()  # puts back any extra a test removed
        for name in _fake_modules():
            if name != "libcamera":
                sys.modules.pop(name, None)


@pytest.fixture(params=["ours", "alt"])
def camera(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> Iterator[Camera]:
    """Each test once per fake."""
    if request.param == "ours":
        _install_fake("libcamera", monkeypatch)
        fake = _install_fake("picamera2", monkeypatch)
        try:
            yield Ours(fake)
        finally:
            fake.shutdown()
    else:
        module, rig = request.getfixturevalue("alt_picamera2")
        yield Alt(module, rig)

