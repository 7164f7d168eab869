"""How much of each landmark a frame shows: exact visible fractions per band.

For each landmark, a fine grid of sample rays covers its whole image extent
(inside the frame or not). Each ray is cast twice: against the landmark alone
and against every object of the scene. A band's visible fraction is the number
of rays that hit that band in the full scene (and fall inside the frame)
over the number that hit it alone, so it is a ratio of image areas, measured
in the image the renderer draws: hidden behind a nearer landmark, robot or
distractor, or cut off by the frame edge, both count as not visible. The rays
follow a low-discrepancy (R2) sequence over the extent, about 11 per pixel
and at most :data:`SAMPLES` per landmark, so a fraction is good to a few
tenths of a percent.
"""

from __future__ import annotations

from typing import List, Optional, Tuple

import numpy as np

from .._compat import frozen
from .camera import _coefficients, _undistort, cylinder_bbox_px
from .lights import Shader
from .parts import build
from .scene import Scene
from .shapes import PARTS, Cyl, Hits, Primitive
from .trace import trace

SAMPLES = 16000
MIN_SPACING_PX = 0.3
_PLASTIC = 1.324717957244746  # x³ = x + 1
FINDABLE = 0.6  # both bands at least this visible: the landmark counts as findable
BLUE, WHITE, RED = 0, 1, 2


@frozen
class Visibility:
    """Visible fractions (0–1) of one landmark's bands and of its whole silhouette."""

    red: float
    white: float
    blue: float
    overall: float

    @property
    def findable(self) -> bool:
        """Both bands at least :data:`FINDABLE` visible."""
        return self.red >= FINDABLE and self.blue >= FINDABLE


def _sample_rays(scene: Scene, box: Tuple[float, float, float, float]
                 ) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sample rays over an image extent: normalised (x, y) and an in-frame mask."""
    u0, v0, u1, v1 = box[0] - 1.0, box[1] - 1.0, box[2] + 1.0, box[3] + 1.0
    n = int(min(SAMPLES, (u1 - u0) * (v1 - v0) / MIN_SPACING_PX**2))
    i = np.arange(n, dtype=np.float64)
    # the R2 low-discrepancy sequence: no edge direction lines up with the samples
    u = u0 + (u1 - u0) * np.modf(0.5 + i / _PLASTIC)[0]
    v = v0 + (v1 - v0) * np.modf(0.5 + i / _PLASTIC**2)[0]
    cam = scene.camera
    inside = (u >= -0.5) & (u < cam.width_px - 0.5) & (v >= -0.5) & (v < cam.height_px - 0.5)
    x, y = (u - cam.cx_px) / cam.fx_px, (v - cam.cy_px) / cam.fy_px
    if cam.has_distortion:
        x, y = _undistort(x, y, cam, _coefficients(cam))
        inside &= np.isfinite(x)
        x, y = np.nan_to_num(x, nan=1e6), np.nan_to_num(y, nan=1e6)
    return x, y, inside


def _overlaps(a: Primitive, b: Primitive, h: float) -> bool:
    """Whether ``b`` could hide part of ``a`` (angular extents from the camera overlap)."""
    ax0, ax1, ay0, ay1, az0, az1 = a.extent()
    bx0, bx1, by0, by1, bz0, bz1 = b.extent()
    if bz0 >= az1:
        return False  # wholly behind
    def span(x0: float, x1: float, z0: float, z1: float) -> Tuple[float, float]:
        zs = (max(z0, 1e-6), max(z1, 1e-6))
        r = [x / z for x in (x0, x1) for z in zs]
        return min(r), max(r)
    a0, a1 = span(ax0, ax1, az0, az1)
    b0, b1 = span(bx0, bx1, bz0, bz1)
    c0, c1 = span(ay0 - h, ay1 - h, az0, az1)
    d0, d1 = span(by0 - h, by1 - h, bz0, bz1)
    return b0 <= a1 and a0 <= b1 and d0 <= c1 and c0 <= d1


def _fractions(alone: np.ndarray, seen: np.ndarray, base: int) -> Visibility:
    def frac(parts: Tuple[int, ...]) -> float:
        ids = [base + p for p in parts]
        total = np.isin(alone, ids).sum()
        return float(np.isin(seen, ids).sum() / total) if total else 0.0
    return Visibility(frac((RED,)), frac((WHITE,)), frac((BLUE,)),
                      frac((BLUE, WHITE, RED, PARTS - 2, PARTS - 1)))


def landmark_visibility(scene: Scene) -> List[Visibility]:
    """Visible fractions of every landmark of ``scene``, in ``scene.landmarks`` order."""
    prims, where = build(scene)
    shade = Shader(np.array([0.0, 1.0, 0.0]), 1.0)  # radiance is not looked at
    h, g = scene.camera_height_m, scene.geometry
    out: List[Visibility] = []
    for lm, k in zip(scene.landmarks, where):
        own = prims[k]
        assert isinstance(own, Cyl)
        box: Optional[Tuple[float, float, float, float]] = cylinder_bbox_px(
            scene, lm.x_m, lm.z_m, g.radius_m, own.y0, own.y1)
        if box is None:
            out.append(Visibility(0.0, 0.0, 0.0, 0.0))
            continue
        x, y, inside = _sample_rays(scene, box)
        alone = Hits.empty(x.shape)
        trace(x, -y, h, own, shade, alone)
        on = np.flatnonzero(alone.ident >= 0)  # only rays that meet the landmark matter
        dx, dy = x[on], -y[on]
        seen = alone.view(on)
        for j, other in enumerate(prims):
            if j != k and _overlaps(own, other, h):
                trace(dx, dy, h, other, shade, seen)
        seen_ident = np.where(inside[on], seen.ident, -1)
        out.append(_fractions(alone.ident, seen_ident, own.ident))
    return out
