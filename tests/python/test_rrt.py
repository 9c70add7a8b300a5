"""a2ml.rrt_connect and a2ml.scene_clearance on a MotionBenchMaker problem
(tests/data/mbm): a path that keeps the clearance, the same path for the same
seed, and typed errors for bad obstacles and unreachable ends."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import a2ml

ROOT = Path(__file__).resolve().parents[2]


def problem(index: int = 0) -> dict[str, Any]:
    data = json.loads((ROOT / "tests" / "data" / "mbm" / "table_pick.json").read_text())
    p: dict[str, Any] = data["problems"][index]
    return p


def panda() -> a2ml.Robot:
    return a2ml.Robot.from_urdf(ROOT / "robots" / "panda.urdf")


def test_a_path_keeps_the_clearance_and_repeats_per_seed() -> None:
    robot, p = panda(), problem()
    result = a2ml.rrt_connect(robot, p["obstacles"], p["start"], p["goals"], seed=3)
    waypoints = result["waypoints"]
    assert waypoints.shape[1] == 7 and waypoints.shape[0] >= 2
    assert np.allclose(waypoints[0], p["start"])
    assert np.allclose(waypoints[-1], p["goals"][result["goal"]])
    for a, b in zip(waypoints[:-1], waypoints[1:]):
        steps = max(1, int(np.ceil(np.abs(b - a).sum() * 1.5 / 2e-3)))
        for k in range(steps + 1):
            q = a + (b - a) * k / steps
            assert a2ml.scene_clearance(robot, p["obstacles"], q) >= 0.01
    again = a2ml.rrt_connect(robot, p["obstacles"], p["start"], p["goals"], seed=3)
    assert np.array_equal(again["waypoints"], waypoints)


def test_bad_obstacles_and_blocked_ends_raise() -> None:
    robot, p = panda(), problem()
    with pytest.raises(ValueError, match="type"):
        a2ml.rrt_connect(robot, [{"type": "cone", "position": [0, 0, 0]}], p["start"], p["goals"])
    with pytest.raises(ValueError, match="radius"):
        a2ml.scene_clearance(robot, [{"type": "sphere", "position": [1, 0, 0]}], p["start"])
    with pytest.raises(TypeError):
        a2ml.scene_clearance(robot, [3], p["start"])  # type: ignore[list-item]
    # A ball around the whole arm: the start is not clear.
    ball = [{"type": "sphere", "position": [0, 0, 0.5], "radius": 2.0}]
    with pytest.raises(a2ml.PlanError, match="start"):
        a2ml.rrt_connect(robot, ball, p["start"], p["goals"])
