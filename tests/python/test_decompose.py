"""The Python API of the decomposition: a2ml.decompose on the shipped
examples (types I and IV, explicit actions), the shape of the returned data
against the TypedDicts, the robot argument, DecomposeError and determinism."""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import a2ml
from a2ml import A2mlError, DecomposeError, Decomposition, Robot, Task, UrdfError

TESTS_DIR = Path(__file__).resolve().parent
EXAMPLES = TESTS_DIR / ".." / ".." / "examples"
ROBOT_FROM_TESTS = "../../robots/coman_right_arm.urdf"


def load(name: str) -> Task:
    return a2ml.load(EXAMPLES / name)


def same(a: object, b: object) -> bool:
    """Deep equality of plain data holding numpy arrays: same keys, same
    types, bit-identical arrays."""
    if isinstance(a, np.ndarray):
        return (
            isinstance(b, np.ndarray)
            and a.dtype == b.dtype
            and a.shape == b.shape
            and bool(np.array_equal(a, b))
        )
    if isinstance(a, dict):
        return (
            isinstance(b, dict)
            and list(a) == list(b)
            and all(same(a[k], b[k]) for k in a)
        )
    if isinstance(a, list):
        return (
            isinstance(b, list)
            and len(a) == len(b)
            and all(same(x, y) for x, y in zip(a, b))
        )
    return type(a) is type(b) and a == b


def check_shape(d: Decomposition, task: Task) -> None:
    """Every dict has exactly the keys its TypedDict declares, joint vectors
    are (7,) float64, and the segments chain from the start."""
    assert set(d) == a2ml.Decomposition.__required_keys__
    assert d["task"] == task.name
    assert d["start"].shape == (7,) and d["start"].dtype == np.float64
    q = d["start"]
    for action in d["actions"]:
        assert set(action) == a2ml.PlannedAction.__required_keys__
        assert task.actions[action["index"]]["name"] == action["name"]
        assert action["segments"]
        for segment in action["segments"]:
            assert set(segment) == a2ml.PlannedSegment.__required_keys__
            assert segment["space"] in ("cpsa", "hat")
            assert segment["pattern"] in ("path", "goal", "mixed")
            assert segment["duration"] > 0.0
            assert isinstance(segment["duration_raised"], bool)
            for key in ("start", "end"):
                assert segment[key].shape == (7,) and segment[key].dtype == np.float64
                assert np.all(np.isfinite(segment[key]))
            np.testing.assert_array_equal(segment["start"], q)
            q = segment["end"]
            for primitive in segment["primitives"]:
                assert primitive["kind"] in ("goal", "path", "hold")
                assert primitive["variables"]
        for report in action["optimisations"]:
            assert set(report) == a2ml.OptReport.__required_keys__
            assert report["solver"] in ("Opt1", "Opt2")
            assert report["evaluations"] > 0


def test_path_by_is_four_type_i_actions() -> None:
    task = load("construct_path_by.a2ml")
    d = a2ml.decompose(task)
    check_shape(d, task)
    np.testing.assert_allclose(d["start"], np.radians([0, -20, 0, -60, 0, 10, 0]))
    names = ["swing_out", "swing_in", "open_elbow", "close_elbow"]
    assert [a["name"] for a in d["actions"]] == names
    assert [a["index"] for a in d["actions"]] == [0, 1, 2, 3]
    for action in d["actions"]:
        assert action["type"] == "i"
        assert action["type_number"] == 1
        assert action["description"] == "one path constraint, no goal"
        assert action["goal_space"] is None
        assert action["secondary_goal_space"] is None
        assert action["optimisations"] == []
        (segment,) = action["segments"]
        assert segment["pattern"] == "path"
        assert segment["solver"] == "auto"
        assert segment["relaxed"] == []
    swing_out = d["actions"][0]
    assert swing_out["path_space"] == "cpsa"
    assert d["actions"][2]["path_space"] == "hat"
    (by,) = [p for p in swing_out["segments"][0]["primitives"] if p["kind"] == "path"]
    assert by["variables"] == ["swivel"]
    assert by["feature"]["kind"] == "by"
    assert by["feature"]["angle"] == pytest.approx(math.radians(20))


def test_type_iv_forward_bar() -> None:
    task = load("type_iv_forward_bar.a2ml")
    d = a2ml.decompose(task)
    check_shape(d, task)
    (action,) = d["actions"]
    assert action["name"] == "rise_along_line"
    assert action["type"] == "iv"
    assert action["type_number"] == 4
    assert action["goal_space"] == "hat"
    assert action["secondary_goal_space"] is None
    assert action["path_space"] == "cpsa"
    (report,) = action["optimisations"]
    assert report["solver"] == "Opt2"
    # The goal is 0.40 m up the line (see the example's header).
    (size,) = report["sizes"]
    assert size == pytest.approx(0.40, abs=0.01)
    assert 0.0 <= report["residual"] < 1e-2
    patterns = [s["pattern"] for s in action["segments"]]
    assert "mixed" in patterns
    segment = action["segments"][patterns.index("mixed")]
    assert segment["space"] == "cpsa"
    assert segment["solver"] == "rrt"
    (line,) = [p for p in segment["primitives"] if p["kind"] == "path"]
    assert line["variables"] == ["pw"]
    assert line["feature"]["kind"] == "line"
    assert line["feature"]["length"] == pytest.approx(size)
    goals = [p for p in segment["primitives"] if p["kind"] == "goal"]
    assert goals and all(set(p["goal"]) == set(p["variables"]) for p in goals)
    robot = Robot.from_urdf(task.robot)
    end = segment["end"]
    assert np.all(end >= robot.lower - 1e-9) and np.all(end <= robot.upper + 1e-9)
    # The wrist ends `size` up the line from where it started.
    start_pw, _, _ = robot.cpsa(segment["start"])
    end_pw, _, _ = robot.cpsa(end)
    direction = np.array([0.356, 0.0, 0.935])
    np.testing.assert_allclose(
        end_pw - start_pw, size * direction / np.linalg.norm(direction), atol=1e-3
    )


EXPLICIT = f"""\
robot "{ROBOT_FROM_TESTS}"
start [0, -20, 0, -60, 0, 10, 0] deg

task swing {{
  action out_and_back explicit {{
    segment 1 s {{ θsw.path(by 20 deg) +Pa (Pw Ow).hold }}
    +Tr segment {{ θsw.path(by -20 deg) +Pa (Pw Ow).hold }}
  }}
  action out explicit {{
    solver qp
    segment {{ Pw.hold +Pa Ow.hold +Pa θsw.path(by 10 deg) }}
  }}
}}
"""


def test_explicit_actions_have_no_classification() -> None:
    task = a2ml.parse(EXPLICIT, TESTS_DIR / "swing.a2ml")
    d = a2ml.decompose(task)
    check_shape(d, task)
    assert [a["name"] for a in d["actions"]] == ["out_and_back", "out"]
    for action in d["actions"]:
        assert action["type"] is None
        assert action["type_number"] is None
        assert action["description"] is None
        assert action["goal_space"] is None
        assert action["secondary_goal_space"] is None
        assert action["path_space"] is None
        assert action["optimisations"] == []
    # The segments as written, primitives shaped as in Task.actions.
    first, second = d["actions"][0]["segments"]
    assert first["duration"] >= 1.0
    assert [s["space"] for s in (first, second)] == ["cpsa", "cpsa"]
    assert [s["pattern"] for s in (first, second)] == ["path", "path"]
    assert first["solver"] == "auto"
    written = task.actions[0]["segments"][0]["primitives"]
    assert [p["variables"] for p in first["primitives"]] == [p["variables"] for p in written]
    assert [p["kind"] for p in first["primitives"]] == ["path", "hold"]
    assert first["primitives"][0]["feature"]["angle"] == pytest.approx(math.radians(20))
    # Out and back: the arm ends where it started.
    np.testing.assert_allclose(second["end"], first["start"], atol=1e-6)
    (third,) = d["actions"][1]["segments"]
    assert third["solver"] == "qp"


def test_explicit_robot_gives_the_same_result() -> None:
    task = load("type_iv_forward_bar.a2ml")
    robot = Robot.from_urdf(task.robot)
    assert same(a2ml.decompose(task, robot), a2ml.decompose(task))
    assert same(a2ml.decompose(task, robot=robot), a2ml.decompose(task, robot=None))


@pytest.mark.parametrize(
    "name", ["construct_path_by.a2ml", "type_iv_forward_bar.a2ml", "type_vii_column.a2ml"]
)
def test_deterministic(name: str) -> None:
    task = load(name)
    first: Any = a2ml.decompose(task)
    assert same(first, a2ml.decompose(task))
    # And from an equal task parsed afresh.
    assert same(first, a2ml.decompose(a2ml.parse(task.source, task.path)))


def test_threads_share_a_task_and_robot() -> None:
    # The GIL is released during the decomposition; concurrent calls on the
    # same objects agree.
    task = load("type_vii_column.a2ml")
    robot = Robot.from_urdf(task.robot)
    expected = a2ml.decompose(task, robot)
    with ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(lambda _: a2ml.decompose(task, robot), range(8)))
    assert all(same(r, expected) for r in results)


def test_results_are_fresh_copies() -> None:
    task = load("construct_path_by.a2ml")
    d = a2ml.decompose(task)
    d["start"][:] = 0.0
    d["actions"].clear()
    again = a2ml.decompose(task)
    assert len(again["actions"]) == 4
    assert np.any(again["start"] != 0.0)


def test_no_start_raises_decompose_error() -> None:
    text = (
        f'robot "{ROBOT_FROM_TESTS}"\n'
        "task idle { action swing { path θsw by 10 deg, Pw hold, Ow hold } }\n"
    )
    task = a2ml.parse(text, TESTS_DIR / "idle.a2ml")
    with pytest.raises(DecomposeError, match="no `start`") as info:
        a2ml.decompose(task)
    assert isinstance(info.value, A2mlError)
    assert "idle" in str(info.value)


def test_bad_robot_file_raises_urdf_error(tmp_path: Path) -> None:
    urdf = tmp_path / "arm.urdf"
    urdf.write_text('<robot name="stub"><link name="base"/></robot>\n')
    text = (
        'robot "arm.urdf"\n'
        "start [0, -20, 0, -60, 0, 10, 0] deg\n"
        "task t { action a { path θsw by 10 deg, Pw hold, Ow hold } }\n"
    )
    task = a2ml.parse(text, tmp_path / "t.a2ml")
    with pytest.raises(UrdfError):
        a2ml.decompose(task)
    # Removed after parsing: still a UrdfError, not an OSError.
    urdf.unlink()
    with pytest.raises(UrdfError):
        a2ml.decompose(task)
    # The robot argument is used instead of the task's file.
    robot = Robot.from_urdf(TESTS_DIR.parents[1] / "robots" / "coman_right_arm.urdf")
    d = a2ml.decompose(task, robot)
    assert [a["type"] for a in d["actions"]] == ["i"]


def test_wrong_argument_types() -> None:
    task = load("construct_path_by.a2ml")
    with pytest.raises(TypeError):
        a2ml.decompose("construct_path_by.a2ml")  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        a2ml.decompose(task, "robot.urdf")  # type: ignore[arg-type]
