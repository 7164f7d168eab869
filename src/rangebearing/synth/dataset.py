"""Sets of synthetic frames with their truth: in memory, or written to a folder.

A folder holds ``000000.png`` … (or ``.jpg``), ``truth.csv`` (see
:mod:`rangebearing.evaluation.truth`) and ``camera.yaml``, the ``camera:`` config section
of the intrinsics the frames were rendered with (loadable with ``--config``).
"""

from __future__ import annotations

import dataclasses
import os
import re
from pathlib import Path
from typing import Any, Callable, Iterator, List, Optional, Tuple, Union

import cv2
import numpy as np
import yaml

from ..core.types import CameraIntrinsics
from ..errors import SceneError
from ..evaluation.truth import TruthRow, write_truth
from .presets import PRESETS, scene_sequence
from .render import render
from .scene import DEFAULT_CAMERA, Scene
from .visibility import landmark_visibility

FORMATS = ("png", "jpg")
TRUTH_FILE = "truth.csv"
CAMERA_FILE = "camera.yaml"
_FRAME_FILE = re.compile(r"^\d{6}\.(png|jpg)$")


def frame_name(index: int, fmt: str = "png") -> str:
    """``000012.png`` for frame 12."""
    return f"{index:06d}.{fmt}"


def scene_truth(scene: Scene, frame: str) -> List[TruthRow]:
    """Truth rows for a scene: every landmark the frame shows any part of, in scene order.

    Range and bearing are exact; ``visible``, ``red_visible``, ``blue_visible``
    and ``findable`` come from :func:`.visibility.landmark_visibility` (hidden
    behind nearer things or cut off by the frame edge both count as not
    visible); ``robot`` is the landmark's ``robot_id`` when it has one.
    """
    rows = []
    for lm, vis in zip(scene.landmarks, landmark_visibility(scene)):
        if vis.overall > 0.0:
            rows.append(TruthRow(frame, lm.range_m, lm.bearing_rad, vis.overall, vis.red, vis.blue,
                                 vis.findable, lm.robot_id if lm.robot_id >= 0 else None))
    return rows


def _whole(v: object) -> bool:
    return isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v >= 0


def _check(frames: int, seed: int, preset: str, fmt: str, jpeg_quality: int) -> None:
    problems = []
    if not _whole(frames):
        problems.append(f"frames must be a whole number >= 0, got {frames!r}")
    if not _whole(seed):
        problems.append(f"seed must be a whole number >= 0, got {seed!r}")
    if preset not in PRESETS:
        problems.append(f"preset {preset!r} is not one of {', '.join(PRESETS)}")
    if fmt not in FORMATS:
        problems.append(f"format {fmt!r} is not one of {', '.join(FORMATS)}")
    if not 1 <= jpeg_quality <= 100:
        problems.append(f"jpeg_quality must be 1-100, got {jpeg_quality!r}")
    if problems:
        raise SceneError(problems, "synth")


def _encode(image: np.ndarray, fmt: str, jpeg_quality: int) -> bytes:
    params = [int(cv2.IMWRITE_JPEG_QUALITY), int(jpeg_quality)] if fmt == "jpg" else []
    ok, buf = cv2.imencode(f".{fmt}", image, params)
    if not ok:
        raise OSError(f"OpenCV could not encode a {fmt} image")
    return buf.tobytes()


def _frames(frames: int, seed: int, preset: str, camera: CameraIntrinsics, fmt: str
            ) -> Iterator[Tuple[str, np.ndarray, List[TruthRow]]]:
    scene_seq, noise_seq = np.random.SeedSequence(seed).spawn(2)
    scene_rng, noise_rng = np.random.default_rng(scene_seq), np.random.default_rng(noise_seq)
    for i, scene in enumerate(scene_sequence(scene_rng, preset, frames, camera)):
        name = frame_name(i, fmt)
        yield name, render(scene, noise_rng), scene_truth(scene, name)


def generate(frames: int, seed: int, preset: str = "paper",
             camera: CameraIntrinsics = DEFAULT_CAMERA, fmt: str = "png",
             jpeg_quality: int = 90) -> Iterator[Tuple[str, np.ndarray, List[TruthRow]]]:
    """Render frames in memory: ``(name, BGR uint8 image, truth rows)`` per frame.

    The images are exactly what :func:`write_dataset` writes for the same
    arguments (``fmt="jpg"`` passes each frame through JPEG and back).
    """
    _check(frames, seed, preset, fmt, jpeg_quality)
    for name, image, rows in _frames(frames, seed, preset, camera, fmt):
        if fmt == "jpg":
            data = np.frombuffer(_encode(image, fmt, jpeg_quality), np.uint8)
            image = cv2.imdecode(data, cv2.IMREAD_COLOR)
        yield name, image, rows


def camera_yaml(camera: CameraIntrinsics) -> str:
    """The ``camera:`` config section for these intrinsics."""
    section = {k: (list(v) if isinstance(v, tuple) else v)
               for k, v in dataclasses.asdict(camera).items()}
    return yaml.safe_dump({"camera": section}, sort_keys=False, default_flow_style=None)


def write_dataset(out_dir: Union[str, os.PathLike], frames: int, seed: int,
                  preset: str = "paper", fmt: str = "png", jpeg_quality: int = 90,
                  camera: CameraIntrinsics = DEFAULT_CAMERA, overwrite: bool = False,
                  wrap: Optional[Callable[[Iterator[Any]], Iterator[Any]]] = None,
                  ) -> List[TruthRow]:
    """Write frames, ``truth.csv`` and ``camera.yaml`` into ``out_dir``; return the truth.

    ``wrap`` wraps the frame iterator (a progress bar). Each frame file appears
    whole (written aside, then renamed), and ``truth.csv`` is written however
    the loop ends, so an interrupted run (KeyboardInterrupt, re-raised) leaves
    frames ``0..n-1`` with their truth, a consistent smaller dataset.

    Raises
    ------
    FileExistsError
        ``out_dir`` already holds frames or a truth file and ``overwrite`` is
        false (stale frames would pass for frames without a landmark).
    SceneError
        A bad argument (frames, seed, preset, format, quality).
    """
    _check(frames, seed, preset, fmt, jpeg_quality)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise NotADirectoryError(f"{out} exists and is not a folder")
    out.mkdir(parents=True, exist_ok=True)
    stale = sorted(p for p in out.iterdir() if _FRAME_FILE.match(p.name) or p.name == TRUTH_FILE)
    if stale and not overwrite:
        raise FileExistsError(f"{out} already holds {len(stale)} frame or truth file(s); "
                              "choose an empty folder or overwrite")
    for p in stale:
        p.unlink()
    truth: List[TruthRow] = []
    items = _frames(frames, seed, preset, camera, fmt)
    try:
        for name, image, rows in wrap(items) if wrap else items:
            tmp = out / f".{name}.part"
            tmp.write_bytes(_encode(image, fmt, jpeg_quality))
            os.replace(tmp, out / name)
            truth.extend(rows)
    finally:
        for part in out.glob(".*.part"):
            part.unlink()
        write_truth(out / TRUTH_FILE, truth)
        (out / CAMERA_FILE).write_text(camera_yaml(camera), encoding="utf-8")
    return truth
