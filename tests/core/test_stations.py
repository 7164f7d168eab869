"""Station plans and the per-station check."""

import math

import pytest

from rangebearing.core.stations import Station, check_station, default_plan, parse_plan
from rangebearing.errors import CalibrationError

HFOV = 2 * math.atan(320 / 634)  # the default camera: 53.6°


def test_default_plan_covers_the_range_and_the_field_of_view():
    plan = default_plan(HFOV)
    ranges = [s.range_m for s in plan]
    assert min(ranges) == 0.2 and max(ranges) == 1.4
    bearings = [math.degrees(s.bearing_rad) for s in plan]
    assert max(bearings) == round(0.75 * math.degrees(HFOV) / 2) == 20
    assert min(bearings) == -20
    assert sum(1 for s in plan if s.bearing_rad == 0) == 8
    assert all(abs(s.bearing_rad) < HFOV / 2 for s in plan)
    assert len({s.name for s in plan}) == len(plan)


def test_instruction_gives_tape_measure_coordinates():
    assert Station("a", 0.3, 0.0).instruction() == "place a landmark 0.30 m straight ahead"
    text = Station("b", 0.5, math.radians(-30)).instruction()
    assert text == "place a landmark 0.50 m 30° to the right (0.433 m ahead, 0.250 m right)"


def test_parse_plan_reads_degrees_left_positive():
    plan = parse_plan("range_m,bearing_deg,name\n0.3,0,near\n0.8, -15 ,\n")
    assert plan[0] == Station("near", 0.3, 0.0)
    assert plan[1].name == "s02" and plan[1].bearing_rad == pytest.approx(math.radians(-15))


@pytest.mark.parametrize(
    ("text", "match"),
    [("range,bearing\n1,2\n", "missing column"), ("range_m,bearing_deg\nx,0\n", ":2: range_m"),
     ("range_m,bearing_deg\n-1,0\n", "above 0"), ("range_m,bearing_deg\n1,95\n", "±80"),
     ("range_m,bearing_deg\n", "no stations")],
)
def test_parse_plan_refuses_bad_rows(text, match):
    with pytest.raises(CalibrationError, match=match):
        parse_plan(text, "plan.csv")


ST = Station("s", 0.5, math.radians(10))


def test_steady_station_near_where_asked_is_ok():
    frames = [[(0.52 + 0.001 * (i % 2), math.radians(10.5)), (1.2, -0.3)] for i in range(6)]
    c = check_station(ST, frames)
    assert c.ok and c.found == 6
    assert c.range_m == pytest.approx(0.5205)


def test_missing_frames_moving_landmark_and_wrong_place_are_told_apart():
    assert check_station(ST, [[(0.5, 0.17)], []]).reason == "landmark found in 1 of 2 frames"
    moving = check_station(ST, [[(0.45, 0.17)], [(0.55, 0.17)]])
    assert not moving.ok and moving.reason.startswith("not steady")
    elsewhere = check_station(ST, [[(0.9, 0.17)]] * 3)
    assert not elsewhere.ok and "is it where asked" in elsewhere.reason
