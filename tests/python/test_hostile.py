"""Generated hostile inputs through the Python API: task text with extreme numbers and
extreme arguments to plan. Each call returns or raises an a2ml error (or ValueError /
OSError); a Rust panic would surface as pyo3's PanicException, which fails the test.

A2ML_HOSTILE_CASES sets the number of generated tasks (default 40)."""

from __future__ import annotations

import os
import random
from pathlib import Path

import a2ml
from a2ml import A2mlError

ROBOT = Path(__file__).resolve().parents[2] / "robots" / "coman_right_arm.urdf"
EXTREMES = ["0", "-0", "1e-320", "1e-9", "0.05", "-0.2", "1", "90", "1e9", "1e19", "1e200",
            "1e308", "-1e308", "1e400"]
CASES = int(os.environ.get("A2ML_HOSTILE_CASES", "40"))


def task_text(rng: random.Random) -> str:
    n = [rng.choice(EXTREMES) for _ in range(10)]
    return (
        f'robot "{ROBOT}"\nstart [0, {n[0]}, 0, -60, 0, 10, 0] deg\n'
        f"scene {{ b = box at [{n[1]}, 0, 0] size [{n[2]}, 0.1, 0.1] }}\n"
        f"settings {{ rate {n[3]} Hz  seed 7 }}\n"
        f"task t {{\n  action a {{\n    path Pw line [{n[4]}, {n[5]}, 0] {n[6]} m, Ow hold, θsw hold\n"
        f"    duration {n[7]} s\n  }}\n}}\n"
    )


def test_generated_tasks_raise_a2ml_errors_or_plan() -> None:
    rng = random.Random(21)
    robot = a2ml.Robot.from_urdf(ROBOT)
    outcomes = {"invalid": 0, "refused": 0, "planned": 0}
    for _ in range(CASES):
        try:
            task = a2ml.parse(task_text(rng))
        except A2mlError:
            outcomes["invalid"] += 1
            continue
        try:
            a2ml.plan(task, rate=rng.choice([1e-3, 1.0, 20.0, 1e19, 1e308]), seed=2**64 - 1,
                      robot=robot)
            outcomes["planned"] += 1
        except (A2mlError, ValueError):
            outcomes["refused"] += 1
    assert sum(outcomes.values()) == CASES
    assert outcomes["invalid"] > 0


def test_extreme_arguments_to_robot_calls_raise() -> None:
    robot = a2ml.Robot.from_urdf(ROBOT)
    for value in [float("nan"), float("inf"), 1e308, -1e308]:
        q = [value] * 7
        for call in (robot.fk, robot.cpsa, robot.hat, robot.jacobian, robot.centers):
            try:
                call(q)
            except (A2mlError, ValueError):
                pass
