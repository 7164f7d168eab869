"""Render a :class:`~.scene.Scene` to a BGR uint8 frame, as a Pi camera would see it.

Two passes of per-pixel ray casting (vectorised numpy):

1. one ray through every pixel centre gives depth, surface id and radiance;
2. every pixel next to an id change (a silhouette, a band edge, the horizon),
   and every pixel of a landmark whose extent is small, is re-rendered with
   ``supersample²`` rays on a jittered N-rooks pattern (every ray in its own
   1/``supersample²`` column and row of the pixel) and averaged in linear
   light, so band areas and centroids are area-weighted: against an exact
   pixel-integrated reference, band centroids are within 0.02 px and the band
   spacing L within 0.05 %.

Then the sensor: optical blur, exposure and white balance, shot and read
noise, clipping, gamma, 8-bit quantisation (or, for the newer presets, the
auto-exposed Bayer camera of :mod:`.sensor`).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import List, Optional, Tuple

import cv2
import numpy as np

from . import isp
from .camera import Rect, cylinder_bbox_px, pixel_rect, ray_grid
from .scene import Scene
from .sensor import develop_sensor
from .trace import Cyl, Primitive, Shader, build, trace, trace_background

MAX_MOTION_STEPS = 7
SMALL_LANDMARK_PX = 2500  # image extents up to this many pixels are supersampled whole


def _rect_of(scene: Scene, prim: Primitive) -> Optional[Rect]:
    x0, x1, y0, y1, z0, z1 = prim.extent()
    cam = scene.camera
    if z1 <= 1e-6:
        return None
    if z0 <= 1e-6:
        return (0, cam.height_px, 0, cam.width_px)
    xs = np.array([x0, x1, x0, x1])[:, None] / np.array([z0, z0, z1, z1])[None, :]
    ys = (scene.camera_height_m - np.array([y0, y1, y0, y1]))[:, None] / np.array([z0, z0, z1, z1])
    return pixel_rect(cam, (xs.min(), xs.max()), (ys.min(), ys.max()))


_M1, _M2 = np.uint64(0xFF51AFD7ED558CCD), np.uint64(0xC4CEB9FE1A85EC53)


def _offsets(rows: np.ndarray, cols: np.ndarray, n: int) -> Tuple[np.ndarray, np.ndarray]:
    """Sub-pixel sample offsets (K, n²): N-rooks strata, jittered per pixel and sample.

    Every sample's du (and dv) is uniform within its own 1/n² stratum, so the
    coverage of a vertical or horizontal edge is unbiased, and the jitter (a
    fixed hash of row, column and sample: the same pixel always gets the same
    offsets) stops straight edges from snapping to 1/n² of a pixel.
    """
    a, b = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    su, sv = (a * n + b).ravel(), (b * n + a).ravel()
    k = (rows.astype(np.uint64) * np.uint64(0x9E3779B97F4A7C15)
         + cols.astype(np.uint64) * np.uint64(0xBF58476D1CE4E5B9))[:, None]
    k = k + np.arange(n * n, dtype=np.uint64)[None, :] * np.uint64(0x94D049BB133111EB)
    k ^= k >> np.uint64(33)
    k *= _M1
    k ^= k >> np.uint64(33)
    k *= _M2
    k ^= k >> np.uint64(33)
    ju = (k & np.uint64(0xFFFFFF)).astype(np.float64) / 2**24
    jv = ((k >> np.uint64(24)) & np.uint64(0xFFFFFF)).astype(np.float64) / 2**24
    return (su + ju) / n**2 - 0.5, (sv + jv) / n**2 - 0.5


def _edges(ident: np.ndarray) -> np.ndarray:
    d = np.zeros(ident.shape, dtype=np.uint8)
    dh = ident[:, 1:] != ident[:, :-1]
    dv = ident[1:, :] != ident[:-1, :]
    d[:, 1:] |= dh
    d[:, :-1] |= dh
    d[1:, :] |= dv
    d[:-1, :] |= dv
    return cv2.dilate(d, np.ones((3, 3), np.uint8)) > 0


def render_linear(scene: Scene, supersample: int = 4) -> np.ndarray:
    """Anti-aliased linear radiance of a scene, before the sensor (see :func:`render_layers`)."""
    return render_layers(scene, supersample)[0]


def render_layers(scene: Scene, supersample: int = 4) -> Tuple[np.ndarray, np.ndarray]:
    """Anti-aliased linear radiance of a scene, before the sensor.

    Parameters
    ----------
    scene : Scene
        What to draw.
    supersample : int
        Edge pixels get ``supersample**2`` rays; 1 turns anti-aliasing off.

    Returns
    -------
    radiance : numpy.ndarray
        (H, W, 3) float64 linear RGB radiance (reflectance × shading, not yet
        exposed), H and W from ``scene.camera``. Pixels whose ray the
        distortion model cannot invert are black.
    depth_m : numpy.ndarray
        (H, W) depth (Z) of what each pixel centre's ray hits (inf: nothing).
    """
    cam, h = scene.camera, scene.camera_height_m
    grid = ray_grid(cam)
    dx, dy = grid.x, -grid.y
    prims, landmarks = build(scene)
    shade = Shader.from_scene(scene, prims, landmarks)
    if not shade.plain:  # nearest first: hidden surfaces fail the depth test before shading
        prims.sort(key=lambda p: p.extent()[4])
    hits = trace_background(dx, dy, scene, shade)
    rects: List[Optional[Rect]] = [_rect_of(scene, p) for p in prims]
    for prim, rect in zip(prims, rects):
        if rect is not None:
            idx = (slice(rect[0], rect[1]), slice(rect[2], rect[3]))
            trace(dx[idx], dy[idx], h, prim, shade, hits.view(idx))
    nan = np.isnan(dx)
    hits.ident[nan] = -1
    out = hits.rad
    out[nan] = 0.0
    depth = hits.t
    if supersample <= 1:
        return out, depth
    flag = _edges(hits.ident)
    near_landmark = np.zeros_like(flag)
    for prim, rect in zip(prims, rects):
        if isinstance(prim, Cyl) and len(prim.bounds) > 1 and rect is not None:
            r0, r1, c0, c1 = rect
            # a far landmark's bands may be thinner than a pixel: take its whole extent
            if (r1 - r0) * (c1 - c0) <= SMALL_LANDMARK_PX:
                flag[r0:r1, c0:c1] = True
            near_landmark[r0:r1, c0:c1] = True
    flag &= ~nan
    coarse = scene.imaging.edge_supersample
    if 0 < coarse < supersample:  # edges away from every landmark get fewer rays
        fine = flag & near_landmark
        _resample(out, np.nonzero(flag & ~near_landmark), coarse, scene, shade, prims, rects)
        flag = fine
    _resample(out, np.nonzero(flag), supersample, scene, shade, prims, rects)
    return out, depth


def _resample(out: np.ndarray, at: Tuple[np.ndarray, np.ndarray], n: int, scene: Scene,
              shade: Shader, prims: List[Primitive], rects: List[Optional[Rect]]) -> None:
    """Replace the pixels ``at`` by the mean of ``n²`` jittered N-rooks rays each."""
    rows, cols = at
    if rows.size == 0:
        return
    grid, h = ray_grid(scene.camera), scene.camera_height_m
    du, dv = _offsets(rows, cols, int(n))
    sx = grid.x[at][:, None] + grid.jxx[at][:, None] * du + grid.jxy[at][:, None] * dv
    sy = grid.y[at][:, None] + grid.jyx[at][:, None] * du + grid.jyy[at][:, None] * dv
    sub = trace_background(sx, -sy, scene, shade)
    for prim, rect in zip(prims, rects):
        if rect is None:
            continue
        r0, r1, c0, c1 = rect
        inside = np.flatnonzero((rows >= r0) & (rows < r1) & (cols >= c0) & (cols < c1))
        if inside.size:
            part = sub.view(inside)
            trace(sx[inside], -sy[inside], h, prim, shade, part)
            sub.put(inside, part)
    out[rows, cols] = sub.rad.mean(axis=1)


@functools.lru_cache(maxsize=4)
def _gamma_lut(gamma: float) -> np.ndarray:
    x = np.arange(65536, dtype=np.float64) / 65535.0
    return np.round(255.0 * x**gamma).astype(np.uint8)


def _tone_lut(gamma: float, tone: str) -> np.ndarray:
    """16-bit linear code → 8 bits through the camera's tone curve (``Imaging.tone``)."""
    return _gamma_lut(gamma) if tone == "gamma" else isp.tone_lut(tone)


def develop(linear: np.ndarray, scene: Scene, rng: Optional[np.random.Generator],
            depth_m: Optional[np.ndarray] = None) -> np.ndarray:
    """Linear radiance to what the camera delivers: BGR uint8 (H, W, 3).

    Blur (optical, linear light) → exposure × white-balance gains → shot and
    read noise (only with an ``rng``) → clip to [0, 1] → gamma → 8 bits.
    With auto exposure, a Bayer mosaic, glare, vignetting or any lens or ISP
    stage, :func:`.sensor.develop_sensor` (defocus needs ``depth_m``).
    """
    im, li = scene.imaging, scene.lighting
    if im.auto_exposure or im.bayer or im.glare > 0 or im.vignetting > 0 or im.isp:
        return develop_sensor(linear, scene, rng, _tone_lut(float(im.gamma), im.tone), depth_m)
    img = linear.astype(np.float32)
    if im.blur_sigma_px > 0.05:
        img = cv2.GaussianBlur(img, (0, 0), im.blur_sigma_px, borderType=cv2.BORDER_REFLECT)
    img *= np.float32(li.exposure) * np.asarray(li.wb_gains, dtype=np.float32)
    if rng is not None and (im.read_noise > 0 or im.shot_noise > 0):
        var = np.float32(im.read_noise**2) + np.float32(im.shot_noise) * np.maximum(img, 0.0)
        sigma = np.sqrt(var)
        img += sigma * rng.standard_normal(img.shape, dtype=np.float32)
    np.clip(img, 0.0, 1.0, out=img)
    idx = (img * 65535.0 + 0.5).astype(np.uint16)
    rgb = np.take(_tone_lut(float(im.gamma), im.tone), idx)
    return cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)


def render(scene: Scene, rng: Optional[np.random.Generator] = None, *,
           supersample: int = 4) -> np.ndarray:
    """Render one frame.

    Parameters
    ----------
    scene : Scene
        Camera, landmarks, distractors, room, light and sensor.
    rng : numpy.random.Generator or None
        Draws the sensor noise; ``None`` renders without noise. Nothing else
        is random, so the same scene and the same rng state give the same frame.
    supersample : int
        Rays per edge pixel are ``supersample**2`` (default 16).

    Returns
    -------
    numpy.ndarray
        (H, W, 3) uint8 in OpenCV's BGR order.
    """
    linear, depth = render_layers(scene, supersample)
    steps = motion_steps(scene)
    if steps > 1:
        linear = _blurred(scene, linear, steps, supersample)
    return develop(linear, scene, rng, depth)


def _blurred(scene: Scene, linear: np.ndarray, steps: int, supersample: int) -> np.ndarray:
    """The mean of ``steps`` moments of the exposure (the scene is the middle one), each
    re-rendered only where a moving robot is during the exposure."""
    e, cam = scene.imaging.exposure_s, scene.camera
    rect = None
    for lm in scene.landmarks:
        if lm.velocity_mps == (0.0, 0.0) and lm.yaw_rate_radps == 0.0:
            continue
        foot = 1.6 * (lm.body.footprint_m if lm.body else scene.robot_radius_m)
        for end in (lm.moved(-e / 2), lm.moved(e / 2)):
            box = cylinder_bbox_px(scene, end.x_m, end.z_m, foot, 0.0, end.base_height_m + scene.geometry.height_m)
            if box is None:
                continue
            r = (int(box[1]) - 3, int(box[3]) + 5, int(box[0]) - 3, int(box[2]) + 5)
            rect = r if rect is None else (min(rect[0], r[0]), max(rect[1], r[1]),
                                           min(rect[2], r[2]), max(rect[3], r[3]))
    if rect is None:
        return linear
    r0, r1 = max(rect[0], 0), min(rect[1], cam.height_px)
    c0, c1 = max(rect[2], 0), min(rect[3], cam.width_px)
    if r1 <= r0 or c1 <= c0:
        return linear
    crop = dataclasses.replace(cam, cx_px=cam.cx_px - c0, cy_px=cam.cy_px - r0, width_px=c1 - c0,
                               height_px=r1 - r0)
    total = linear[r0:r1, c0:c1].copy()
    for k in range(steps):
        dt = e * ((k + 0.5) / steps - 0.5)
        if abs(dt) > 1e-12:
            moved = dataclasses.replace(scene, camera=crop, landmarks=tuple(lm.moved(dt) for lm in scene.landmarks))
            total += render_layers(moved, min(supersample, 2))[0]  # the moments smooth edges too
    out = linear.copy()
    out[r0:r1, c0:c1] = total / steps
    return out


def motion_steps(scene: Scene) -> int:
    """Moments of the exposure to average: one per ~2 px the fastest landmark moves
    in the image during ``exposure_s``, odd (1: no blur), at most :data:`MAX_MOTION_STEPS`."""
    e = scene.imaging.exposure_s
    if e <= 0:
        return 1
    fx = scene.camera.fx_px
    px = 0.0
    for lm in scene.landmarks:
        speed = math.hypot(*lm.velocity_mps) + abs(lm.yaw_rate_radps) * 0.05
        px = max(px, fx * speed * e / max(lm.z_m, 0.05))
    n = min(max(math.ceil(px / 2.0), 1), MAX_MOTION_STEPS)
    return int(n if n % 2 else n + 1)  # odd: the middle moment is the scene itself
