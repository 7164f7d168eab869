"""Threshold requests: every bad key named, missing keys kept, applied to detection parameters."""

from __future__ import annotations

import pytest

from rangebearing.config import Config
from rangebearing.errors import RequestError
from rangebearing.view.thresholds import Thresholds, parse

CURRENT = Thresholds(((0, 10), (165, 179)), ((98, 132),), 90, 25)


def test_partial_update_keeps_the_rest() -> None:
    new = parse({"s_min": 120, "blue_hue": [[100, 130]]}, CURRENT)
    assert new == Thresholds(((0, 10), (165, 179)), ((100, 130),), 120, 25)


def test_round_trip_through_json() -> None:
    assert parse(CURRENT.as_json(), Thresholds((), (), 0, 0)) == CURRENT


@pytest.mark.parametrize(
    ("body", "words"),
    [
        ({"s_min": 256}, ["s_min", "outside [0, 255]"]),
        ({"v_min": -1}, ["v_min", "outside"]),
        ({"s_min": 12.5}, ["s_min", "integer"]),
        ({"s_min": True}, ["s_min", "integer"]),
        ({"s_min": "90"}, ["s_min", "integer"]),
        ({"red_hue": [[10, 5]]}, ["red_hue", "low 10 is above high 5"]),
        ({"red_hue": [[0, 180]]}, ["red_hue", "outside [0, 179]"]),
        ({"red_hue": []}, ["red_hue", "list"]),
        ({"blue_hue": [[1, 2, 3]]}, ["blue_hue", "pair"]),
        ({"blue_hue": [[0, 1]] * 5}, ["blue_hue", "at most 4"]),
        ({"hue": 3}, ["hue", "unknown key"]),
        ([1, 2], ["JSON object"]),
    ],
)
def test_bad_values_are_named(body: object, words: list) -> None:
    with pytest.raises(RequestError) as err:
        parse(body, CURRENT)
    for w in words:
        assert w in str(err.value)


def test_every_problem_at_once() -> None:
    with pytest.raises(RequestError) as err:
        parse({"s_min": 300, "v_min": 300, "x": 1}, CURRENT)
    msg = str(err.value)
    assert "s_min" in msg and "v_min" in msg and "x: unknown key" in msg


def test_apply_to_detection_parameters() -> None:
    det = Config().detection
    new = Thresholds(((1, 2),), ((3, 4),), 5, 6).apply(det)
    assert (new.red_hue, new.blue_hue, new.s_min, new.v_min) == (((1, 2),), ((3, 4),), 5, 6)
    assert new.median_ksize == det.median_ksize
    assert Thresholds.of(new) == Thresholds(((1, 2),), ((3, 4),), 5, 6)
