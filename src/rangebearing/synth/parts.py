"""A scene's objects as ray-casting primitives: landmarks, the robots under them, distractors.

A landmark with ``body=None`` stands on a plain dark cylinder (the original
presets); with a :class:`~.scene.RobotBody` it stands on a Zumo-like robot:
two rubber tracks, a chassis between them, a steel blade at the front, a board
stack (the Raspberry Pi), a mast up to the landmark, and the robot's own camera
board on a bracket at the front edge, level with the middle of the white body
(the only place a camera at about 0.10 m can look out from under a landmark
spanning 0.065–0.135 m); seen from the front it hides the middle of the white
body and its bracket a sliver of the blue band.
"""

from __future__ import annotations

import math
from typing import List, Tuple

import numpy as np

from .scene import (
    BLUE_PAINT,
    CAP_GREY,
    RED_PAINT,
    ROBOT_BODY,
    ROBOT_TOP,
    WHITE_PAINT,
    LandmarkPose,
    RobotBody,
    Scene,
)
from .shapes import ID_OBJECT, PARTS, Cuboid, Cyl, OBox, Primitive


def _robot(lm: LandmarkPose, body: RobotBody, lens: float, ident: int) -> List[Primitive]:
    psi = lm.heading_rad
    f = np.array([math.cos(psi), math.sin(psi)])  # forward in (x, z)
    side = np.array([-math.sin(psi), math.cos(psi)])
    c = np.array([lm.x_m, lm.z_m])
    out: List[Primitive] = []

    def box(at: np.ndarray, half_long: float, half_across: float, y0: float, y1: float,
            colour: Tuple[float, float, float]) -> None:
        out.append(OBox(float(at[0]), float(at[1]), half_long, half_across, y0, y1, psi,
                        np.array(colour), ident + PARTS * len(out)))

    off = body.width_m / 2 - body.track_width_m / 2
    for sign in (-1.0, 1.0):
        box(c + sign * off * side, body.length_m / 2, body.track_width_m / 2, 0.0,
            body.track_height_m, body.track_colour)
    inner = body.width_m / 2 - body.track_width_m
    box(c, body.length_m * 0.46, inner, 0.008, body.chassis_top_m, body.chassis_colour)
    box(c + (body.length_m / 2 + 0.003) * f, 0.0025, body.width_m / 2, 0.002, 0.022,
        body.blade_colour)
    top = min(body.board_top_m, lm.base_height_m)
    if top > body.chassis_top_m:
        box(c, body.board_length_m / 2, body.board_width_m / 2, body.chassis_top_m, top,
            body.board_colour)
    else:
        top = body.chassis_top_m
    # the robot's own camera looks out from the front edge, on a bracket, at ``lens``
    front = c + (body.length_m / 2 - 0.008) * f
    box(front - 0.004 * f, 0.002, 0.002, top, lens - 0.008, ROBOT_BODY)
    box(front, 0.003, 0.009, lens - 0.008, lens + 0.008, body.camera_colour)
    if lm.base_height_m > top + 1e-4:
        out.append(Cyl(lm.x_m, lm.z_m, body.mast_radius_m, top, lm.base_height_m,
                       np.array([top]), np.array([body.mast_colour]), np.array(body.mast_colour),
                       ident + PARTS * len(out)))
    return out


def build(scene: Scene) -> Tuple[List[Primitive], List[int]]:
    """The scene's primitives, each with its own block of ids, and the index in
    that list of every landmark's cylinder (in ``scene.landmarks`` order)."""
    out: List[Primitive] = []
    where: List[int] = []
    g = scene.geometry

    def ident() -> int:
        return ID_OBJECT + PARTS * len(out)

    for lm in scene.landmarks:
        b = lm.base_height_m
        if lm.body is None:
            out.append(Cyl(lm.x_m, lm.z_m, scene.robot_radius_m, 0.0, b, np.array([0.0]),
                           np.array([ROBOT_BODY]), np.array(ROBOT_TOP), ident()))
        else:
            out.extend(_robot(lm, lm.body, b + g.height_m / 2, ident()))
        bounds = np.array([b, b + g.band_height_m, b + g.height_m - g.band_height_m])
        red, white, blue = scene.paint or (RED_PAINT, WHITE_PAINT, BLUE_PAINT)
        colours = np.array([blue, white, red])
        where.append(len(out))
        out.append(Cyl(lm.x_m, lm.z_m, g.radius_m, b, b + g.height_m, bounds, colours,
                       np.array(CAP_GREY), ident(), glossy=True))
    for cy in scene.cylinders:
        out.append(Cyl(cy.x_m, cy.z_m, cy.radius_m, cy.bottom_m, cy.top_m, np.array([cy.bottom_m]),
                       np.array([cy.colour]), np.array(cy.colour), ident()))
    for bx in scene.boxes:
        out.append(Cuboid(bx.x_m - bx.width_m / 2, bx.x_m + bx.width_m / 2, bx.bottom_m, bx.top_m,
                          bx.z_m - bx.depth_m / 2, bx.z_m + bx.depth_m / 2, np.array(bx.colour),
                          ident()))
    return out, where


def primitives(scene: Scene) -> List[Primitive]:
    """The scene's objects as primitives, each with its own block of ids."""
    return build(scene)[0]
