"""Visible fractions in the truth, against cases worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rangebearing.synth import Box, LandmarkPose, Scene, scene_truth
from rangebearing.synth.scene import RobotBody
from rangebearing.synth.shapes import Cuboid, Hits, OBox
from rangebearing.synth.trace import Shader, trace
from rangebearing.synth.visibility import landmark_visibility

GREY = (0.5, 0.5, 0.5)


def test_unhidden_landmark_is_wholly_visible():
    (vis,) = landmark_visibility(Scene(landmarks=(LandmarkPose(0.6, 0.2),)))
    assert (vis.red, vis.white, vis.blue, vis.overall) == (1.0, 1.0, 1.0, 1.0)
    assert vis.findable


def test_left_half_behind_a_box_edge_on_the_axis():
    # the box's right edge is the plane X = 0, which holds the landmark's axis and the
    # camera: at bearing 0 the silhouette is symmetric about that plane, so half is hidden
    box = Box(-0.25, 0.3, 0.5, 0.02, 0.0, 0.5, GREY)
    (vis,) = landmark_visibility(Scene(landmarks=(LandmarkPose(0.6, 0.0),), boxes=(box,)))
    for part in (vis.red, vis.white, vis.blue, vis.overall):
        assert part == pytest.approx(0.5, abs=0.005)
    assert not vis.findable


def test_box_top_at_camera_height_hides_everything_below_the_horizon():
    # a box whose top is at the camera's height hides, at any depth behind it, exactly
    # what is below that height: the blue band (0.065-0.080 m), half the white body
    # (0.080-0.120 m, hidden to 0.100 m), and no red (0.120-0.135 m)
    box = Box(0.0, 0.3, 0.6, 0.05, 0.0, 0.10, GREY)
    scene = Scene(landmarks=(LandmarkPose(0.8, 0.05),), boxes=(box,), camera_height_m=0.10)
    (vis,) = landmark_visibility(scene)
    assert vis.blue == 0.0 and vis.red == 1.0
    assert vis.white == pytest.approx(0.5, abs=0.01)
    assert vis.overall == pytest.approx(0.5, abs=0.01)
    # raise the landmark so the horizon cuts its blue band in half
    raised = Scene(landmarks=(LandmarkPose(0.8, 0.05, base_height_m=0.0925),), boxes=(box,))
    (vis,) = landmark_visibility(raised)
    assert vis.blue == pytest.approx(0.5, abs=0.01) and not vis.findable


def test_a_nearer_landmark_hides_a_farther_one_and_the_truth_drops_it():
    near, far = LandmarkPose(0.3, 0.0), LandmarkPose(0.9, 0.0)
    scene = Scene(landmarks=(near, far), robot_radius_m=0.01)
    vis = landmark_visibility(scene)
    assert vis[0].overall == 1.0 and vis[1].overall == 0.0
    rows = scene_truth(scene, "f")
    assert [r.range_m for r in rows] == [0.3]
    # side by side, a little apart: the far one comes back whole
    apart = Scene(landmarks=(near, LandmarkPose(0.9, 0.12)), robot_radius_m=0.01)
    assert [v.overall for v in landmark_visibility(apart)] == [1.0, 1.0]


def test_partly_hidden_by_a_nearer_landmark():
    # the far landmark's axis lies on the near one's silhouette edge: about half is hidden
    near = LandmarkPose(0.4, 0.0)
    edge = math.asin(0.0175 / 0.4)
    far = LandmarkPose(1.0, edge)
    (_, vis) = landmark_visibility(Scene(landmarks=(near, far), robot_radius_m=0.01))
    assert 0.45 < vis.overall < 0.55
    assert vis.red == pytest.approx(vis.blue, abs=0.01)


def test_the_frame_edge_counts_as_hiding():
    scene = Scene()
    cam = scene.camera
    at_edge = math.atan((cam.cx_px + 0.5) / cam.fx_px)  # the axis on the left frame edge
    (vis,) = landmark_visibility(Scene(landmarks=(LandmarkPose(0.7, at_edge),)))
    assert vis.overall == pytest.approx(0.5, abs=0.02)
    (gone,) = landmark_visibility(Scene(landmarks=(LandmarkPose(0.7, at_edge + 0.2),)))
    assert gone.overall == 0.0


def test_truth_rows_carry_visibility_findable_and_robot():
    scene = Scene(landmarks=(LandmarkPose(0.6, 0.0, robot_id=7, body=RobotBody()),),
                  boxes=(Box(-0.25, 0.3, 0.5, 0.02, 0.0, 0.5, GREY),))
    (row,) = scene_truth(scene, "000000.png")
    assert row.robot == 7 and row.findable is False
    assert row.visible == pytest.approx(0.5, abs=0.01)
    assert row.red_visible == pytest.approx(0.5, abs=0.01)


def test_turned_box_matches_the_axis_aligned_one():
    rng = np.random.default_rng(0)
    dx, dy = rng.uniform(-0.3, 0.3, 20000), rng.uniform(-0.3, 0.2, 20000)
    shade = Shader.from_scene(Scene())
    a, b, c = Hits.empty(dx.shape), Hits.empty(dx.shape), Hits.empty(dx.shape)
    trace(dx, dy, 0.1, Cuboid(-0.05, 0.07, 0.0, 0.09, 0.4, 0.44, np.array(GREY), 1024), shade, a)
    trace(dx, dy, 0.1, OBox(0.01, 0.42, 0.06, 0.02, 0.0, 0.09, 0.0, np.array(GREY), 1024), shade, b)
    # a quarter turn swaps the box's length and width
    trace(dx, dy, 0.1, OBox(0.01, 0.42, 0.02, 0.06, 0.0, 0.09, math.pi / 2, np.array(GREY), 1024),
          shade, c)
    assert np.array_equal(np.isfinite(a.t), np.isfinite(b.t)) and np.isfinite(a.t).sum() > 1000
    hit = np.isfinite(a.t)
    assert np.allclose(a.t[hit], b.t[hit]) and np.allclose(a.t[hit], c.t[hit])
    assert np.allclose(a.rad[hit], b.rad[hit])
