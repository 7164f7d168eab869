"""Fixtures shared across the suite: the picamera2 fake and a small static recorded clip."""

from __future__ import annotations

import atexit
import importlib.util
import os
import shutil
import sys
import tempfile
from pathlib import Path
from types import ModuleType
from typing import Iterator, List

# The package's caches (parsed configs, dataclass methods: rangebearing._compat.cache_dir) go to a temp dir of
# this run, never the user's ~/.cache; set before rangebearing is imported. Subprocesses inherit it.
if "RANGEBEARING_CACHE" not in os.environ:
    os.environ["RANGEBEARING_CACHE"] = tempfile.mkdtemp(prefix="rb-test-cache-")
    atexit.register(shutil.rmtree, os.environ["RANGEBEARING_CACHE"], True)

import cv2
import numpy as np
import pytest
from hypothesis import settings

from rangebearing.evaluation.truth import TruthRow
from rangebearing.synth import Imaging, LandmarkPose, Scene, render

# No timing asserts in unit tests: hypothesis' default 200 ms deadline per example failed a protocol
# property test on a loaded machine (470 ms on a first call, 0.03 ms on the retry: FlakyFailure).
settings.register_profile("rangebearing", deadline=None)
settings.load_profile("rangebearing")

FAKES = Path(__file__).resolve().parent / "fakes"

# Two neighbours standing still: every frame of the clip has the same truth.
STATIC_SCENE = Scene(
    landmarks=(LandmarkPose(0.45, 0.20), LandmarkPose(0.80, -0.15)),
    wall_distance_m=2.5,
    imaging=Imaging(blur_sigma_px=0.5, read_noise=0.004, shot_noise=0.0005),
)


def _install_fake(name: str, monkeypatch: pytest.MonkeyPatch) -> ModuleType:
    """Put tests/fakes/<name> into sys.modules as ``name`` (undone after the test)."""
    init = FAKES / name / "__init__.py"
    spec = importlib.util.spec_from_file_location(name, init, submodule_search_locations=[str(init.parent)])
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, name, module)
    spec.loader.exec_module(module)
    return module


@pytest.fixture
def fake_picamera2(monkeypatch: pytest.MonkeyPatch) -> Iterator[ModuleType]:
    """A fresh fake ``picamera2`` (and ``libcamera``) in sys.modules for one test.

    ``fake.WORLD`` is the camera hardware: stall it, skip frames, set the producer.
    The real picamera2 is never imported.
    """
    _install_fake("libcamera", monkeypatch)  # picamera2 imports it
    fake = _install_fake("picamera2", monkeypatch)
    yield fake
    fake.shutdown()


def write_static_clip(directory: Path, frames: int, seed: int = 0) -> List[TruthRow]:
    """Write ``frames`` noisy PNG renders of :data:`STATIC_SCENE`; returns one frame's truth."""
    directory.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    for i in range(frames):
        cv2.imwrite(str(directory / f"{i:06d}.png"), render(STATIC_SCENE, rng))
    return [TruthRow("*", lm.range_m, lm.bearing_rad) for lm in STATIC_SCENE.landmarks]


@pytest.fixture(scope="session")
def static_clip(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 12-frame recorded clip of two still landmarks (truth in :data:`STATIC_SCENE`)."""
    path = tmp_path_factory.mktemp("static") / "clip"
    write_static_clip(path, 12)
    return path
