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


def test_obstacles_converted_once_plan_the_same_path() -> None:
    robot, p = panda(), problem()
    prepared = a2ml.Obstacles(robot, p["obstacles"])
    assert len(prepared) == len(p["obstacles"])
    from_dicts = a2ml.rrt_connect(robot, p["obstacles"], p["start"], p["goals"], seed=5)
    from_prepared = a2ml.rrt_connect(robot, prepared, p["start"], p["goals"], seed=5)
    assert np.array_equal(from_prepared["waypoints"], from_dicts["waypoints"])
    assert from_prepared["collision_checks"] == from_dicts["collision_checks"]
    # A second robot object of the same URDF builds its own arm model: the same path again.
    again = a2ml.rrt_connect(panda(), prepared, p["start"], p["goals"], seed=5)
    assert np.array_equal(again["waypoints"], from_dicts["waypoints"])
    q = from_dicts["waypoints"][1]
    assert a2ml.scene_clearance(robot, prepared, q) == a2ml.scene_clearance(robot, p["obstacles"], q)


def test_obstacles_refuse_bad_dicts_and_a_robot_rooted_elsewhere() -> None:
    robot, p = panda(), problem()
    with pytest.raises(ValueError, match="type"):
        a2ml.Obstacles(robot, [{"type": "cone", "position": [0, 0, 0]}])
    prepared = a2ml.Obstacles(robot, p["obstacles"])
    # The same arm with its URDF root 0.5 m further below the first joint: the obstacles'
    # positions in {b} would differ.
    text = (ROOT / "robots" / "panda.urdf").read_text()
    assert text.count('xyz="0 0 0.333"') == 1
    lower = a2ml.Robot.from_urdf_string(text.replace('xyz="0 0 0.333"', 'xyz="0 0 0.833"'))
    with pytest.raises(ValueError, match="converted for a robot"):
        a2ml.rrt_connect(lower, prepared, p["start"], p["goals"])
    with pytest.raises(ValueError, match="converted for a robot"):
        a2ml.scene_clearance(lower, prepared, p["start"])
