"""The dependency floors pyproject.toml declares are the versions the floor job tests (item 19)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_declared_floors_are_the_tested_ones() -> None:
    declared = dict(re.findall(r'"([a-z-]+)>=([0-9.]+)"', (ROOT / "pyproject.toml").read_text("utf-8")))
    tested = dict(re.findall(r"^([a-z-]+)==([0-9.]+)$", (ROOT / ".ci" / "floors.txt").read_text("utf-8"), re.M))
    assert tested, "no pinned floor versions"
    for name, version in tested.items():
        floor = declared[name]
        assert version.startswith(floor + ".") or version == floor, (name, floor, version)
    assert (ROOT / ".ci" / "floor").read_text("utf-8").count("floors.txt") >= 1
