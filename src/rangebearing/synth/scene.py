"""What a synthetic frame shows: frozen scene descriptions with exact geometry.

World frame: camera centre at ``(0, camera_height_m, 0)``, X to the camera's
right, Y up, Z forward along the (horizontal) optical axis. A landmark at range
``r`` and bearing ``θ`` (positive to the LEFT) has its axis at
``X = -r·sin θ, Z = r·cos θ``. Colours are linear RGB reflectances in [0, 1].
"""

from __future__ import annotations

import dataclasses
import math
from typing import Optional, Tuple

from .._compat import frozen
from ..core.types import CameraIntrinsics, LandmarkGeometry
from ..errors import SceneError
from .imaging import Imaging, imaging_problems

RGB = Tuple[float, float, float]

RED_PAINT: RGB = (0.70, 0.07, 0.06)
BLUE_PAINT: RGB = (0.06, 0.12, 0.65)
WHITE_PAINT: RGB = (0.85, 0.85, 0.85)
CAP_GREY: RGB = (0.45, 0.45, 0.45)
ROBOT_BODY: RGB = (0.06, 0.06, 0.06)
ROBOT_TOP: RGB = (0.13, 0.13, 0.13)

DEFAULT_CAMERA_HEIGHT_M = 0.10
DEFAULT_BASE_HEIGHT_M = 0.065
DEFAULT_ROBOT_RADIUS_M = 0.05
DEFAULT_CAMERA = CameraIntrinsics()


@frozen
class RobotBody:
    """A Zumo-like robot under a landmark: tracked chassis, boards, a mast.

    Heights are from the floor; lengths along the robot's heading. The mast is
    a dark standoff from the top board up to the landmark's base (none when the
    base is no higher than the board); ``mast_colour`` may be slightly bluish
    or reddish, as a 3D-printed or anodised part would be.
    """

    length_m: float = 0.098
    width_m: float = 0.090
    track_width_m: float = 0.016
    track_height_m: float = 0.036
    chassis_top_m: float = 0.034
    board_top_m: float = 0.050
    board_width_m: float = 0.056
    board_length_m: float = 0.085
    mast_radius_m: float = 0.012
    chassis_colour: RGB = (0.035, 0.035, 0.038)
    track_colour: RGB = (0.025, 0.025, 0.025)
    board_colour: RGB = (0.05, 0.16, 0.07)
    blade_colour: RGB = (0.50, 0.50, 0.52)
    mast_colour: RGB = (0.04, 0.04, 0.045)
    camera_colour: RGB = (0.05, 0.16, 0.07)

    @property
    def footprint_m(self) -> float:
        """Radius of the circle around the robot's footprint (blade included)."""
        return math.hypot(self.length_m / 2 + 0.01, self.width_m / 2)


@frozen
class LandmarkPose:
    """One neighbour: its landmark's axis position and the height of its base.

    With ``body=None`` the robot under it is a dark cylinder from the floor up
    to ``base_height_m`` (the original presets); with a :class:`RobotBody` it is
    a Zumo-like robot turned to ``heading_rad`` (0 = facing the camera's +X,
    counter-clockwise seen from above). ``robot_id`` names the robot across the
    frames of a sequence (-1: not tracked). ``velocity_mps`` (world X, Z) and
    ``yaw_rate_radps`` are its motion at this moment: with
    ``Imaging.exposure_s`` > 0 the frame is blurred by it (the pose is the
    middle of the exposure).
    """

    range_m: float
    bearing_rad: float
    base_height_m: float = DEFAULT_BASE_HEIGHT_M
    heading_rad: float = 0.0
    body: Optional[RobotBody] = None
    robot_id: int = -1
    velocity_mps: Tuple[float, float] = (0.0, 0.0)
    yaw_rate_radps: float = 0.0

    def moved(self, dt_s: float) -> LandmarkPose:
        """Where it is ``dt_s`` later, moving as it does now."""
        if self.velocity_mps == (0.0, 0.0) and self.yaw_rate_radps == 0.0:
            return self
        x = self.x_m + self.velocity_mps[0] * dt_s
        z = self.z_m + self.velocity_mps[1] * dt_s
        return dataclasses.replace(self, range_m=math.hypot(x, z), bearing_rad=math.atan2(-x, z),
                                   heading_rad=self.heading_rad + self.yaw_rate_radps * dt_s)

    @property
    def x_m(self) -> float:
        """World X of the axis (negative = left of the camera)."""
        return -self.range_m * math.sin(self.bearing_rad)

    @property
    def z_m(self) -> float:
        """World Z of the axis: the depth along the optical axis (the paper's d_v)."""
        return self.range_m * math.cos(self.bearing_rad)


@frozen
class Spot:
    """A point light (a lamp, a spotlight) at ``position`` aimed at ``target``.

    Irradiance at a surface is ``intensity · colour · max(0, n·l) / d²`` inside
    the cone, fading to nothing between ``cone_deg`` and ``cone_deg + soft_deg``
    off its axis; ``intensity`` 0.25 at 0.5 m adds as much as a full directional
    light. A large ``cone_deg`` makes a bare bulb.
    """

    position: Tuple[float, float, float]
    target: Tuple[float, float, float]
    intensity: float = 0.25
    colour: RGB = (1.0, 1.0, 1.0)
    cone_deg: float = 20.0
    soft_deg: float = 4.0


@frozen
class Cylinder:
    """A plain vertical cylinder of one colour (a distractor)."""

    x_m: float
    z_m: float
    radius_m: float
    bottom_m: float
    top_m: float
    colour: RGB


@frozen
class Box:
    """An axis-aligned box of one colour (a distractor); ``x_m, z_m`` is its centre."""

    x_m: float
    z_m: float
    width_m: float
    depth_m: float
    bottom_m: float
    top_m: float
    colour: RGB


@frozen
class FloorPatch:
    """A rectangle of another colour on the floor (a rug, a tile)."""

    x_min_m: float
    x_max_m: float
    z_min_m: float
    z_max_m: float
    colour: RGB


@frozen
class Poster:
    """A rectangle of another colour on the back wall; with ``emission`` > 0 it
    glows (a bright window: radiance ``colour · emission``, unshaded)."""

    x_min_m: float
    x_max_m: float
    bottom_m: float
    top_m: float
    colour: RGB
    emission: float = 0.0


@frozen
class Lighting:
    """A directional light plus ambient, and the camera's exposure and white balance.

    ``direction`` points from the scene towards the light (world frame, need
    not be unit length). Radiance = albedo · (ambient·ambient_colour +
    (1 − ambient)·max(0, n·l)·colour) plus each spot's share, plus, on the
    landmark's semi-gloss paint, a Blinn-Phong highlight ``gloss · (n·h)^shininess``
    of every light's colour (a spotlight's can clip the band to white).
    ``exposure`` is ignored when the camera runs auto exposure.
    ``light_radius_deg``: the directional light's angular size (a softbox, a
    lamp's diffuser), which softens the shadows :mod:`.ground` casts on the floor.
    ``fresnel`` > 0: the landmark's paint is glossy plastic that mirrors the
    room at grazing angles (Schlick, F₀ = 0.04, times ``fresnel``).
    """

    direction: Tuple[float, float, float] = (-0.35, 0.75, -0.55)
    ambient: float = 0.40
    exposure: float = 1.25
    wb_gains: RGB = (1.0, 1.0, 1.0)
    colour: RGB = (1.0, 1.0, 1.0)
    ambient_colour: RGB = (1.0, 1.0, 1.0)
    spots: Tuple[Spot, ...] = ()
    gloss: float = 0.0
    shininess: float = 60.0
    light_radius_deg: float = 0.0
    fresnel: float = 0.0

    @property
    def plain(self) -> bool:
        """White light, no spots, no highlights: the original shading."""
        return (self.colour == (1.0, 1.0, 1.0) and self.ambient_colour == (1.0, 1.0, 1.0)
                and not self.spots and self.gloss == 0.0 and self.fresnel == 0.0)


@frozen
class Scene:
    """Everything one frame shows. ``wall_distance_m=None`` is an open room.

    ``floor_texture`` and ``wall_texture`` > 0 vary the floor's (and mats') and
    the wall's albedo by about that fraction (a smooth pattern from 0.4 m down
    to 4 mm, as carpet, concrete or painted plaster; ``texture_seed`` picks it).
    ``floor_pattern`` (one of :data:`.surfaces.PATTERNS`, with its
    ``floor_pattern_params`` from :func:`.surfaces.params`) lays planks, tiles
    or carpet pile over the floor (not its mats); ``brick_wall`` lays the wall
    in bricks (:func:`.surfaces.brick_gain`). ``floor_shading`` (under any
    light but the plain one): the floor gets soft shadows and ambient occlusion from what stands on it (:mod:`.ground`);
    ``local_bounce``: landmarks get light bounced off their robot's board and
    the objects right beside them (:mod:`.bounce`). ``paint``: the landmarks' (red,
    white, blue) paint instead of :data:`RED_PAINT`, :data:`WHITE_PAINT`, :data:`BLUE_PAINT`.

    Examples
    --------
    >>> scene = Scene(landmarks=(LandmarkPose(0.5, math.radians(10)),))
    """

    camera: CameraIntrinsics = CameraIntrinsics()
    camera_height_m: float = DEFAULT_CAMERA_HEIGHT_M
    landmarks: Tuple[LandmarkPose, ...] = ()
    geometry: LandmarkGeometry = LandmarkGeometry()
    robot_radius_m: float = DEFAULT_ROBOT_RADIUS_M
    cylinders: Tuple[Cylinder, ...] = ()
    boxes: Tuple[Box, ...] = ()
    floor_colour: RGB = (0.60, 0.60, 0.60)
    floor_patches: Tuple[FloorPatch, ...] = ()
    wall_distance_m: Optional[float] = 1.2
    wall_colour: RGB = (0.78, 0.78, 0.78)
    posters: Tuple[Poster, ...] = ()
    background_colour: RGB = (0.30, 0.30, 0.30)
    floor_texture: float = 0.0
    wall_texture: float = 0.0
    texture_seed: int = 0
    floor_pattern: str = ""
    floor_pattern_params: Tuple[float, ...] = ()
    brick_wall: bool = False
    floor_shading: bool = False
    local_bounce: bool = False
    paint: Optional[Tuple[RGB, RGB, RGB]] = None
    lighting: Lighting = Lighting()
    imaging: Imaging = Imaging()

    def __post_init__(self) -> None:
        problems = []
        if not self.camera_height_m > 0:
            problems.append(f"camera_height_m must be > 0, got {self.camera_height_m}")
        if self.wall_distance_m is not None and not self.wall_distance_m > 0:
            problems.append(f"wall_distance_m must be > 0 or None, got {self.wall_distance_m}")
        for i, lm in enumerate(self.landmarks):
            if not lm.range_m > 0:
                problems.append(f"landmarks[{i}].range_m must be > 0, got {lm.range_m}")
            if not lm.base_height_m >= 0:
                problems.append(f"landmarks[{i}].base_height_m must be >= 0")
        for name in ("cylinders", "boxes"):
            for i, obj in enumerate(getattr(self, name)):
                if not obj.top_m > obj.bottom_m:
                    problems.append(f"{name}[{i}]: top_m must be above bottom_m")
        problems += imaging_problems(self.imaging)
        if problems:
            raise SceneError(problems, "synthetic scene")
