"""The ``photoreal`` presets: the crowd-proof scenes through a real camera's lens and ISP.

An independent path-traced render of the same situations differs from ours
in ways no single preset asks about; these presets put all of them together
(see docs/synth.md, "Photoreal"):

- the Pi Camera v1's fixed-focus lens: defocus by depth (focused 0.8–3 m, so
  a landmark at 0.15–0.3 m is soft), softer corners, lateral colour;
- its ISP: the OV5647 colour matrix (chroma noise), an AWB pulled by the
  frame's colours, edge-aware or bilinear demosaic, colour denoise, luma
  sharpening (halos),
  4:2:0 chroma or JPEG.

``photoreal``        one scene of ``far``, ``lighting``, ``occlusion`` or
                     ``touching`` kind per frame (1–4 robots, 0.15–2 m).
``photoreal-crowd``  ``crowd`` scenes (5–8 robots).
``photoreal-moving`` one ``crowd-moving`` run (same camera, room and paint
                     throughout) whose robots blur over an exposure of
                     8–33 ms (each robot's velocity from its next frame).
"""

from __future__ import annotations

import dataclasses
from typing import Callable, Dict, Iterator, Tuple

import numpy as np

from ..core.types import CameraIntrinsics
from . import isp, surfaces
from . import sampling as d
from .crowd import crowd_scene, far_scene, lighting_scene, occlusion_scene
from .motion import FPS as MOVING_FPS
from .motion import crowd_sequence
from .scene import RGB, Imaging, LandmarkPose, Lighting, Poster, Scene
from .touching import touching_scene

PHOTOREAL_PRESETS = ("photoreal", "photoreal-crowd", "photoreal-moving")
PHOTOREAL_HELP = {
    "photoreal": "far/lighting/occlusion/touching scenes through the Pi Camera v1's lens and ISP "
                 "(defocus, colour matrix, AWB pull, sharpening, 4:2:0/JPEG)",
    "photoreal-crowd": "crowd scenes (5-8 robots) through the same lens and ISP",
    "photoreal-moving": "a crowd-moving run (30 fps, robot ids) through the same lens and ISP, "
                        "moving robots blurred over an 8-33 ms exposure",
}
WOODS: Tuple[RGB, ...] = ((0.55, 0.38, 0.22), (0.68, 0.52, 0.34), (0.35, 0.22, 0.12), (0.75, 0.62, 0.45))
BRICKS: Tuple[RGB, ...] = ((0.42, 0.14, 0.09), (0.50, 0.25, 0.15), (0.62, 0.55, 0.45))
SKIRTING: Tuple[RGB, ...] = ((0.85, 0.85, 0.83), (0.30, 0.20, 0.12), (0.08, 0.08, 0.08), (0.6, 0.6, 0.6))
_KINDS: Dict[str, Callable[[np.random.Generator, CameraIntrinsics], Scene]] = {
    "far": far_scene, "lighting": lighting_scene, "occlusion": occlusion_scene,
    "touching": touching_scene}


def camera_isp(rng: np.random.Generator, scene: Scene) -> Imaging:
    """The scene's camera with the lens and ISP stages of the Pi Camera v1 drawn."""
    im = scene.imaging
    warm = scene.lighting.colour[2] < 0.8 * scene.lighting.colour[0]
    cool = scene.lighting.colour[0] < 0.9 * scene.lighting.colour[2]
    ccm = isp.OV5647_CCMS[0 if warm else 2 if cool else 1]
    fmt = rng.random()
    # the colour matrix amplifies raw noise about 1.5x in luma: less of it on the photosites
    return dataclasses.replace(
        im, read_noise=im.read_noise / 1.5, shot_noise=im.shot_noise / 2.25,
        focus_m=d.log_uniform(rng, 0.8, 3.0), aperture_m=0.00124 * d.uniform(rng, 0.9, 1.1),
        soft_corners_px=d.uniform(rng, 0.2, 1.0), lateral_colour=d.uniform(rng, -1.0, 1.0) * 0.0015,
        ccm=tuple(float(v) for row in ccm for v in row), awb_pull=d.uniform(rng, 0.15, 0.5),
        demosaic="ea" if rng.random() < 0.6 else "bilinear",
        chroma_denoise_px=d.uniform(rng, 0.5, 1.5), sharpen=d.uniform(rng, 0.3, 1.5),
        chroma_420=fmt < 0.4, jpeg_quality=int(rng.integers(75, 96)) if fmt >= 0.7 else 0)


def photoreal_scene(rng: np.random.Generator, preset: str, camera: CameraIntrinsics) -> Scene:
    """One frame of a photoreal preset (see the module docstring)."""
    if preset == "photoreal-moving":
        return next(_moving(rng, 1, camera))
    if preset == "photoreal-crowd":
        scene = crowd_scene(rng, camera)
    else:
        kinds = list(_KINDS)
        scene = _KINDS[kinds[int(rng.integers(len(kinds)))]](rng, camera)
    return dataclasses.replace(scene, imaging=camera_isp(rng, scene), floor_shading=True,
                               local_bounce=True, lighting=paint(rng, scene.lighting), **room(rng, scene))


def room(rng: np.random.Generator, scene: Scene) -> dict:
    """A floor of planks, tiles or carpet (or plain), bricks (most red walls, now and then
    another), and a skirting board along the wall."""
    out: dict = {}
    kind = ("wood", "wood", "tiles", "carpet", "")[int(rng.integers(5))]
    if kind:
        out.update(floor_pattern=kind, floor_pattern_params=surfaces.params(rng, kind))
        if kind == "wood" and rng.random() < 0.6:
            out["floor_colour"] = d.jitter(rng, WOODS[int(rng.integers(len(WOODS)))], 0.03)
    reddish = scene.wall_colour[0] > 1.5 * scene.wall_colour[2]
    if scene.wall_distance_m is not None and rng.random() < (0.7 if reddish else 0.12):
        out["brick_wall"] = True
        if not reddish:
            out["wall_colour"] = d.jitter(rng, BRICKS[int(rng.integers(len(BRICKS)))], 0.02)
    if scene.wall_distance_m is not None and rng.random() < 0.6:
        top = d.uniform(rng, 0.04, 0.12)
        colour = SKIRTING[int(rng.integers(len(SKIRTING)))]
        out["posters"] = (Poster(-50.0, 50.0, 0.0, top, d.jitter(rng, colour, 0.02)), *scene.posters)
    return out


def paint(rng: np.random.Generator, light: Lighting) -> Lighting:
    """The landmark's paint (glossy plastic or matte paper) and the light's size."""
    size = d.uniform(rng, 2.0, 15.0)
    if rng.random() < 0.6:  # glossy plastic: highlights and the room mirrored at the silhouette
        return dataclasses.replace(light, light_radius_deg=size, fresnel=d.uniform(rng, 0.6, 1.0),
                                   gloss=max(light.gloss, d.uniform(rng, 0.05, 0.25)))
    return dataclasses.replace(light, light_radius_deg=size, fresnel=0.0,
                               gloss=min(light.gloss, d.uniform(rng, 0.0, 0.02)),
                               shininess=d.uniform(rng, 5.0, 15.0))


def photoreal_sequence(rng: np.random.Generator, preset: str, frames: int,
                       camera: CameraIntrinsics) -> Iterator[Scene]:
    """``frames`` independent draws of a photoreal preset (consecutive moments for
    ``photoreal-moving``)."""
    if preset == "photoreal-moving":
        yield from _moving(rng, frames, camera)
        return
    for _ in range(frames):
        yield photoreal_scene(rng, preset, camera)


def _moving(rng: np.random.Generator, frames: int, camera: CameraIntrinsics) -> Iterator[Scene]:
    look: dict = {}
    scenes = crowd_sequence(rng, frames + 1, camera)
    now = next(scenes, None)
    for after in scenes:
        assert now is not None
        if not look:
            imaging = dataclasses.replace(camera_isp(rng, now), exposure_s=d.uniform(rng, 0.008, 0.033))
            look = dict(imaging=imaging, floor_shading=True, local_bounce=True,
                        lighting=paint(rng, now.lighting), **room(rng, now))
        yield dataclasses.replace(now, landmarks=tuple(_velocity(a, b) for a, b in
                                                       zip(now.landmarks, after.landmarks)), **look)
        now = after


def _velocity(now: LandmarkPose, after: LandmarkPose) -> LandmarkPose:
    fps = MOVING_FPS
    return dataclasses.replace(now, velocity_mps=((after.x_m - now.x_m) * fps, (after.z_m - now.z_m) * fps),
                               yaw_rate_radps=(after.heading_rad - now.heading_rad) * fps)


def defocus_px(scene: Scene, range_m: float) -> float:
    """Blur-disc diameter (px) the scene's lens gives a point ``range_m`` ahead (0: in focus)."""
    im = scene.imaging
    if im.focus_m <= 0:
        return 0.0
    return im.aperture_m * scene.camera.fx_px * abs(1.0 / range_m - 1.0 / im.focus_m)


__all__ = ["PHOTOREAL_HELP", "PHOTOREAL_PRESETS", "camera_isp", "defocus_px", "photoreal_scene",
           "photoreal_sequence"]
