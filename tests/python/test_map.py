"""The Python API of the swivel obstacle map: a2ml.swivel_map on the paper's
scenario (a Robot, a wrist path through the via points V1 and V2, two
spheres) and on a task's segment, the arrays it returns, the profile checked
against forward kinematics, and the errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

import a2ml

ROOT = Path(__file__).resolve().parent / ".." / ".."
ARM = ROOT / "robots" / "swivel_map_arm.urdf"
EXAMPLE = ROOT / "examples" / "swivel_map_spheres.a2ml"

# The paper's §4 in metres: via points V1, V2, goal G; the two spheres.
POINTS = [[0.0129, 0.0834, 0.0198], [0.0469, 0.0757, 0.0313], [0.070, 0.100, 0.030]]
SPHERES = [
    ("sphere1", [0.033, 0.063, 0.0], 0.020),
    ("sphere2", [0.045, 0.095, 0.010], 0.015),
]


def paper_start(robot: a2ml.Robot, swivel: float) -> NDArray[np.float64]:
    p = np.array([0.3, 0.93, 0.12])
    p /= np.linalg.norm(p)
    f = np.array([0.0, 0.0, 1.0]) - p * p[2]
    f /= np.linalg.norm(f)
    ow = np.column_stack([f, p, np.cross(f, p)])
    q: NDArray[np.float64] = robot.ik_cpsa([0.0, 0.06, 0.0], ow, swivel)
    return q


def test_paper_scenario_map_and_profile() -> None:
    robot = a2ml.Robot.from_urdf(ARM)
    probe = a2ml.swivel_map(
        robot, start=paper_start(robot, 0.0), points=POINTS, duration=5.0,
        spheres=SPHERES, safety_distance=0.0,
    )
    assert probe["labels"].shape == (200, 360) and probe["labels"].dtype == np.int8
    assert probe["t"][0] == 0.0 and abs(probe["t"][-1] - 5.0) < 1e-12
    assert probe["obstacles"] == ["sphere1", "sphere2"]
    # Sphere 1 forbids part of every column; sphere 2 only near the end (METHODS.md §1.6).
    labels = probe["labels"]
    assert (labels == 3).any(axis=1).all()
    first_2 = probe["t"][(labels == 4).any(axis=1)].min()
    assert 3.6 < first_2 < 4.2
    # Start opposite sphere 1's region at t = 0: a profile exists.
    column = probe["swivel"][labels[0] == 3]
    opposite = float(np.angle(-np.exp(1j * column).mean()))
    m = a2ml.swivel_map(
        robot, start=paper_start(robot, opposite), points=POINTS, duration=5.0,
        spheres=SPHERES, safety_distance=0.0,
    )
    assert m["error"] is None, m["error"]
    profile = m["profile"]
    assert profile["q"].shape == (5001, 7) and profile["clearance"] >= 0.0
    # The wrist ends at the goal, the swivel read back by FK is the profile.
    pw, _, swivel = robot.cpsa(profile["q"][-1])
    assert np.linalg.norm(pw - np.array(POINTS[-1])) < 1e-9
    assert abs(np.angle(np.exp(1j * (swivel - profile["swivel"][-1])))) < 1e-9


def test_task_segment_map() -> None:
    m = a2ml.swivel_map(EXAMPLE, action="pass_spheres")
    assert m["error"] is None and m["profile"] is not None
    assert m["labels"].shape == (200, 360)
    assert all(f is None for f in m["faults"])


def test_errors() -> None:
    robot = a2ml.Robot.from_urdf(ARM)
    with pytest.raises(ValueError, match="needs `start`"):
        a2ml.swivel_map(robot, points=POINTS, duration=5.0)
    with pytest.raises(ValueError, match="no action `nope`"):
        a2ml.swivel_map(EXAMPLE, action="nope")
    with pytest.raises(TypeError):
        a2ml.swivel_map(3.5)  # type: ignore[arg-type]
