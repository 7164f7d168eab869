"""The benchmark's frames: one camera per resolution, N landmarks drifting, ArUco and AprilTag markers beside them.

Every contender sees the same frames. A scenario's frames are consecutive
moments of one smooth motion whose period is the number of frames, so cycling
through them (as the tracking contender does) never jumps. The markers the
ArUco and AprilTag contenders look for (one of each per landmark) are painted
into the linear radiance before the sensor model, so they get the same blur
and noise as the landmarks.

:func:`preset_scenario` draws the harder scenes instead (clutter, crowds,
touching robots, moving sequences) from :mod:`rangebearing.synth` presets.
"""

from __future__ import annotations

import dataclasses
import math
from typing import List, Optional, Sequence, Tuple

import cv2
import numpy as np

from rangebearing.config import Config
from rangebearing.core.types import CameraIntrinsics
from rangebearing.synth import Imaging, LandmarkPose, Scene, develop, landmark_bbox_px, render_linear

HFOV_DEG = 53.5  # Pi Camera v1
NEAR_M, FAR_M = 0.5, 1.2  # alternating landmark ranges
WALL_M = 2.0  # beyond the farthest landmark
EDGE_RAD = 0.06  # keeps the outermost landmarks wholly in view while they drift
DRIFT_RAD = 0.010  # bearing amplitude of the drift (≈ 6 px at 640×480)
DRIFT_RANGE_M = 0.02
MARKER_SCALE = 1.3  # marker side / landmark image height
NOISE = Imaging(blur_sigma_px=0.5, read_noise=0.004, shot_noise=0.0005)
Marker = Tuple[int, int, int, int, str]  # x, y, side in px, id, kind ("aruco" | "apriltag")
SEQUENCES = ("sample", "crowd-moving")  # presets whose frames are consecutive moments
MIN_SIDE_PX = {"aruco": 12, "apriltag": 24}  # 6 and 8 cells of at least 2 and 3 px


@dataclasses.dataclass
class ScenarioFrames:
    """One scenario: its camera and config, its frames and what each frame shows."""

    width_px: int
    height_px: int
    n_landmarks: int
    cfg: Config
    frames: List[np.ndarray]
    truth: List[Tuple[LandmarkPose, ...]]
    markers: List[Marker]
    marker_scale: float
    scene_name: str = "clean"
    sequence: bool = True  # consecutive moments of a motion (a tracker may follow them)
    yuv: List[object] = dataclasses.field(default_factory=list)  # each frame's YUV420 stream (as the ISP makes it)
    #: every landmark of each frame's scene, findable or not (a reading of a partly hidden one is no false landmark);
    #: empty: the same as ``truth``
    seen: List[Tuple[LandmarkPose, ...]] = dataclasses.field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.yuv:
            from rangebearing.core.yuv import yuv420_from_bgr

            self.yuv = [yuv420_from_bgr(f) for f in self.frames]

    @property
    def label(self) -> str:
        return f"{self.width_px}×{self.height_px}"

    def count(self, kind: str) -> int:
        """Markers of one kind drawn in every frame."""
        return sum(m[4] == kind for m in self.markers)


def pi_camera(width_px: int, height_px: int) -> CameraIntrinsics:
    """Square pixels, the Pi Camera v1 horizontal field of view, principal point at the centre."""
    f = (width_px / 2.0) / math.tan(math.radians(HFOV_DEG / 2.0))
    return CameraIntrinsics(width_px, height_px, f, f, (width_px - 1) / 2.0, (height_px - 1) / 2.0)


def camera_config(base: Config, cam: CameraIntrinsics) -> Config:
    """``base`` with this camera; the paper model's k (px·m, i.e. f·S) follows the focal length.

    The default pinhole model needs nothing: it is in normalised units.
    """
    k = cam.fy_px * base.landmark.band_spacing_m
    return dataclasses.replace(base, camera=cam, model=dataclasses.replace(base.model, k_px_m=k))


def poses(n: int, cam: CameraIntrinsics, phase: float) -> Tuple[LandmarkPose, ...]:
    """``n`` landmarks at bearings spread evenly across the view, ranges alternating near/far.

    ``phase`` (radians) is the moment of the drift: each landmark sways in
    bearing and range on its own phase, a full period every 2π.
    """
    half = cam.hfov_rad / 2.0 - EDGE_RAD
    # Below 640 px wide the far landmarks come nearer with the width, so that they keep about the image size they
    # have at 640×480 (1.2 m at 320×240 would be a 2.4 m landmark at 640×480, beyond the detector's 2 m envelope).
    far_m = max(NEAR_M + 0.2, FAR_M * min(1.0, cam.width_px / 640.0))
    out = []
    for i in range(n):
        centre = half * (1.0 - 2.0 * (i + 0.5) / n)  # left (positive) first
        own = phase + 2.0 * math.pi * i / max(n, 1)
        bearing = centre + DRIFT_RAD * math.sin(own)
        rng_m = (NEAR_M if i % 2 == 0 else far_m) + DRIFT_RANGE_M * math.cos(own)
        out.append(LandmarkPose(rng_m, bearing))
    return tuple(out)


def _occupied(scenes: Sequence[Scene], pad_px: int) -> np.ndarray:
    """uint8 mask of every pixel a landmark or its robot covers in any of the scenes, padded."""
    cam = scenes[0].camera
    mask = np.zeros((cam.height_px, cam.width_px), np.uint8)
    for scene in scenes:
        for lm in scene.landmarks:
            box = landmark_bbox_px(scene, lm, with_robot=True)
            if box is None:
                continue
            u0, v0, u1, v1 = (round(c) for c in box)
            mask[max(0, v0 - pad_px): max(0, v1 + pad_px + 1), max(0, u0 - pad_px): max(0, u1 + pad_px + 1)] = 1
    return mask


def _first_free(occ: np.ndarray, side: int, step: int) -> Optional[Tuple[int, int]]:
    """Top-left of the first ``side``×``side`` window (row by row) with nothing occupied."""
    h, w = occ.shape
    if side > min(h, w):
        return None
    integral = cv2.integral(occ)
    ys = np.arange(0, h - side + 1, step)
    xs = np.arange(0, w - side + 1, step)
    y0, x0 = ys[:, None], xs[None, :]
    sums = integral[y0 + side, x0 + side] - integral[y0, x0 + side] - integral[y0 + side, x0] + integral[y0, x0]
    free = np.argwhere(sums == 0)
    if free.size == 0:
        return None
    r, c = free[0]
    return int(xs[c]), int(ys[r])


def place_markers(
    scenes: Sequence[Scene], sizes_px: Sequence[float], kinds: Sequence[str] = ("aruco",)
) -> Tuple[List[Marker], float]:
    """Marker squares in free space away from every landmark; shrinks all of them until they fit.

    Every kind gets one marker per size (ids 0, 1, … within a kind). Returns
    the markers and the scale they were drawn at (1 = as asked).
    """
    if not sizes_px:
        return [], 1.0
    cam = scenes[0].camera
    step = max(1, cam.width_px // 160)
    wanted = [(kind, ident, size) for kind in kinds for ident, size in enumerate(sizes_px)]
    for scale in (1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.45, 0.4, 0.35, 0.3):
        occ = _occupied(scenes, pad_px=2 * step)
        placed: List[Marker] = []
        for kind, ident, size in sorted(wanted, key=lambda t: -t[2]):
            side = max(MIN_SIDE_PX.get(kind, 12), round(size * scale))
            quiet = max(4, side // 6)  # one marker cell of wall around each marker
            spot = _first_free(occ, side + 2 * quiet, step)
            if spot is None:
                break
            x, y = spot
            occ[y: y + side + 2 * quiet, x: x + side + 2 * quiet] = 1
            placed.append((x + quiet, y + quiet, side, ident, kind))
        if len(placed) == len(wanted):
            return sorted(placed, key=lambda m: (m[4], m[3])), scale
    raise RuntimeError(f"cannot fit {len(sizes_px)} markers into a {cam.width_px}×{cam.height_px} frame")


def paint_markers(linear: np.ndarray, markers: Sequence[Marker], images: Sequence[np.ndarray]) -> None:
    """Paint printed markers (black 5 %, white 85 % reflectance) into linear radiance, in place.

    Each marker is lit like the surface it covers (its mean radiance over a grey of 0.78).
    """
    for (x, y, side, *_), img in zip(markers, images):
        patch = linear[y: y + side, x: x + side]
        light = float(patch.mean()) / 0.78
        albedo = 0.05 + 0.80 * (img.astype(np.float64) / 255.0)
        patch[...] = (albedo * light)[:, :, None]


def build_scenario(
    base: Config, width_px: int, height_px: int, n: int, n_frames: int, seed: int, marker_images
) -> ScenarioFrames:
    """Render ``n_frames`` noisy frames of ``n`` drifting landmarks with one marker of each kind per landmark.

    ``marker_images`` maps a kind ("aruco", "apriltag") to a function
    ``(ids_and_sides) -> bitmaps`` (see :mod:`bench_aruco`, :mod:`bench_apriltag`);
    a bare function is taken as the ArUco one.
    """
    if callable(marker_images):
        marker_images = {"aruco": marker_images}
    cam = pi_camera(width_px, height_px)
    cfg = camera_config(base, cam)
    scenes = [
        Scene(camera=cam, landmarks=poses(n, cam, 2.0 * math.pi * k / n_frames), wall_distance_m=WALL_M, imaging=NOISE)
        for k in range(n_frames)
    ]
    heights = [cam.fy_px * base.landmark.height_m / lm.range_m for lm in poses(n, cam, 0.0)]
    markers, scale = place_markers(scenes, [MARKER_SCALE * h for h in heights], tuple(marker_images))
    images = [marker_images[m[4]]([(m[3], m[2])])[0] for m in markers]
    rng = np.random.default_rng(seed)
    frames = []
    for scene in scenes:
        linear = render_linear(scene)
        paint_markers(linear, markers, images)
        frames.append(develop(linear, scene, rng))
    return ScenarioFrames(
        width_px, height_px, n, cfg, frames, [s.landmarks for s in scenes], markers, MARKER_SCALE * scale
    )


def preset_scenario(
    base: Config, width_px: int, height_px: int, preset: str, n_frames: int, seed: int
) -> ScenarioFrames:
    """``n_frames`` frames of a :mod:`rangebearing.synth` preset, no markers.

    Presets that are sequences (``sample``, ``crowd-moving``) give consecutive
    moments; the others independent draws. The truth of a frame is what the
    pipeline should find: every landmark the synth marks findable (the
    crowd-proof presets' visibility), or every landmark of the scene; a reading
    of a landmark hidden too much to be findable is neither wanted nor false
    (``seen`` lists every landmark of the scene).
    """
    from rangebearing.synth import scene_sequence

    cam = pi_camera(width_px, height_px)
    cfg = camera_config(base, cam)
    rng = np.random.default_rng(seed)
    scenes = list(scene_sequence(rng, preset, n_frames, cam))
    frames = [develop(render_linear(s), s, rng) for s in scenes]
    truth = [findable(s) for s in scenes]
    n = max((len(t) for t in truth), default=0)
    sequence = preset in SEQUENCES
    seen = [tuple(s.landmarks) for s in scenes]
    return ScenarioFrames(width_px, height_px, n, cfg, frames, truth, [], 1.0, preset, sequence, seen=seen)


def findable(scene: Scene) -> Tuple[LandmarkPose, ...]:
    """The landmarks of a scene a detector should report (all of them when the synth has no visibility)."""
    try:
        from rangebearing.synth.visibility import landmark_visibility
    except ImportError:
        return tuple(scene.landmarks)
    return tuple(lm for lm, vis in zip(scene.landmarks, landmark_visibility(scene)) if vis.findable)
