"""Synthetic camera frames with exact ground truth, for tests, benchmarks and demos.

>>> import numpy as np
>>> from rangebearing.synth import Scene, LandmarkPose, render, random_scene
>>> frame = render(Scene(landmarks=(LandmarkPose(0.5, 0.1),)))   # BGR uint8, no noise
>>> scene = random_scene(np.random.default_rng(0), "wide")
>>> noisy = render(scene, np.random.default_rng(1))

Modules: :mod:`.scene` (what a frame shows), :mod:`.camera` (rays and
projection), :mod:`.trace` (ray casting), :mod:`.render` (the renderer and the
sensor), :mod:`.presets` and :mod:`.clutter` (random scenes), :mod:`.dataset`
(sets of frames with ``truth.csv``).
"""

from __future__ import annotations

from .camera import landmark_bbox_px, project, ray_grid
from .dataset import FORMATS, frame_name, generate, scene_truth, write_dataset
from .presets import PRESETS, Wander, random_scene, sample_plan, sample_scene, scene_sequence
from .render import develop, render, render_linear
from .scene import (
    BLUE_PAINT,
    RED_PAINT,
    WHITE_PAINT,
    Box,
    Cylinder,
    FloorPatch,
    Imaging,
    LandmarkPose,
    Lighting,
    Poster,
    Scene,
)

__all__ = [
    "BLUE_PAINT",
    "FORMATS",
    "PRESETS",
    "RED_PAINT",
    "WHITE_PAINT",
    "Box",
    "Cylinder",
    "FloorPatch",
    "Imaging",
    "LandmarkPose",
    "Lighting",
    "Poster",
    "Scene",
    "Wander",
    "develop",
    "frame_name",
    "generate",
    "landmark_bbox_px",
    "project",
    "random_scene",
    "ray_grid",
    "render",
    "render_linear",
    "sample_plan",
    "sample_scene",
    "scene_sequence",
    "scene_truth",
    "write_dataset",
]
