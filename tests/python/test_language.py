"""The Python API of the task language: a2ml.parse, a2ml.load, the Task data
(SI units, numpy arrays), ParseError locations, I/O errors and pickling."""

from __future__ import annotations

import math
import os
import pickle
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import a2ml
from a2ml import A2mlError, ParseError, Task

TESTS_DIR = Path(__file__).resolve().parent
ROBOT = TESTS_DIR.parents[1] / "robots" / "coman_right_arm.urdf"
# The robot as a task file in TESTS_DIR names it.
ROBOT_FROM_TESTS = "../../robots/coman_right_arm.urdf"

BODY = """\
start [0, -20, 0, -60, 0, 10, 0] deg

scene {
  table = box      at [0.45, 0, -0.30] size [40, 80, 4] cm
  bar   = capsule  from [0.3, -0.3, 0.1] to [0.3, 0.3, 0.1] radius 2 cm
  post  = cylinder at [0.37, 0.05, -0.5] radius 0.03 height 1.0
  ball  = sphere   at [0.3, 0.1, 0.0] radius 5 cm
}

settings { rate 50 Hz  seed 7  transition 20 % }

task push {
  init { holding }
  goal { done }

  action drop "Drop what is in the hand" {
    pre { holding } add { empty } del { holding }
    goal Pw Ow = ([0.25, -0.28, -0.05], rpy(180, 0, 90) deg) > θe = 90 deg
    duration 2 s
  }
  action slide {
    pre { empty } add { done }
    path Pw line [0, 1, 0] 20 cm, Ow hold, θsw hold : hard
    contact { table }
    solver qp
  }
  action turn explicit {
    segment 1.5 s { Os.path(about -r, 30 deg) +Pa (θe Ow).goal(100 deg, axes(f: [1, 0, 0], p: [0, 1, 0])) }
    +Tr segment { (Pw Ow).hold +Pa θsw.goal(30 deg) }
  }
}
"""

VALID = f'robot "{ROBOT_FROM_TESTS}"\n' + BODY


def parse_here(text: str) -> Task:
    """Parses text as if it were a file in the tests folder."""
    return a2ml.parse(text, TESTS_DIR / "task.a2ml")


def same(a: Any, b: Any) -> bool:
    """Deep equality of plain data holding numpy arrays."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return bool(np.array_equal(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return bool(a == b)


@pytest.fixture(scope="module")
def task() -> Task:
    return parse_here(VALID)


def test_header(task: Task) -> None:
    assert task.name == "push"
    assert Path(task.robot).resolve() == ROBOT
    assert task.init == ["holding"]
    assert task.goal == ["done"]
    assert task.settings == {
        "rate": 50.0,
        "solver": "auto",
        "seed": 7,
        "transition": pytest.approx(0.2),
        "frame": "base",
    }


def test_start_in_radians(task: Task) -> None:
    start = task.start
    assert start is not None and list(start) == ["joints"]
    q = start["joints"]
    assert isinstance(q, np.ndarray) and q.shape == (7,) and q.dtype == np.float64
    np.testing.assert_allclose(q, np.radians([0, -20, 0, -60, 0, 10, 0]))


def test_scene_in_metres(task: Task) -> None:
    table, bar, post, ball = task.scene
    assert table["name"] == "table" and table["shape"] == "box"
    np.testing.assert_allclose(table["center"], [0.45, 0.0, -0.30])
    np.testing.assert_allclose(table["size"], [0.40, 0.80, 0.04])
    assert bar["shape"] == "capsule" and bar["radius"] == pytest.approx(0.02)
    np.testing.assert_allclose(bar["a"], [0.3, -0.3, 0.1])
    np.testing.assert_allclose(bar["b"], [0.3, 0.3, 0.1])
    np.testing.assert_array_equal(table["rotation"], np.eye(3))
    rotation = post.pop("rotation")
    assert post == {
        "name": "post",
        "shape": "cylinder",
        "center": pytest.approx(np.array([0.37, 0.05, -0.5])),
        "radius": 0.03,
        "height": 1.0,
    }
    np.testing.assert_array_equal(rotation, np.eye(3))
    assert ball["shape"] == "sphere" and ball["radius"] == pytest.approx(0.05)


def test_rotated_shapes() -> None:
    text = (
        f'robot "{ROBOT_FROM_TESTS}"\n'
        "scene {\n"
        "  shelf = box at [0.4, 0, 0] size [0.2, 0.1, 0.02] rotation rpy(0, 0, 90) deg\n"
        "  post = cylinder at [0.3, 0, 0] radius 0.03 height 0.5 axis [0, 1, 0]\n"
        "  rail = capsule at [0.3, 0, 0.1] radius 0.02 height 0.4 axis [1, 0, 0]\n"
        "}\n"
        "task t { action a { goal θe = 1 } }\n"
    )
    shelf, post, rail = a2ml.parse(text, str(TESTS_DIR / "rotated.a2ml")).scene
    np.testing.assert_allclose(shelf["rotation"] @ [1, 0, 0], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(post["rotation"] @ [0, 0, 1], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(rail["a"], [0.1, 0, 0.1], atol=1e-12)
    np.testing.assert_allclose(rail["b"], [0.5, 0, 0.1], atol=1e-12)


def test_constraint_action_with_priorities(task: Task) -> None:
    drop = task.actions[0]
    assert drop["kind"] == "constraints"
    assert (drop["name"], drop["description"]) == ("drop", "Drop what is in the hand")
    assert (drop["pre"], drop["add"], drop["del"]) == (["holding"], ["empty"], ["holding"])
    assert drop["contact"] == []
    assert drop["solver"] is None and drop["path"] is None
    assert drop["duration"] == 2.0
    goal = drop["goal"]
    assert list(goal["primary"]) == ["pw", "ow"] and list(goal["secondary"]) == ["elbow"]
    np.testing.assert_allclose(goal["primary"]["pw"], [0.25, -0.28, -0.05])
    ow = goal["primary"]["ow"]
    assert ow.shape == (3, 3)
    # rpy(180, 0, 90) deg = Rz(90°) Rx(180°).
    np.testing.assert_allclose(ow, [[0, 1, 0], [1, 0, 0], [0, 0, -1]], atol=1e-12)
    assert goal["secondary"]["elbow"] == pytest.approx(math.pi / 2)


def test_path_action_in_si(task: Task) -> None:
    slide = task.actions[1]
    assert slide["kind"] == "constraints" and slide["solver"] == "qp"
    assert slide["contact"] == ["table"]
    assert slide["goal"] is None and slide["duration"] is None
    path = slide["path"]
    assert path["space"] == "cpsa" and path["hard"] is True
    line, hold_ow, hold_swivel = path["items"]
    assert line["variables"] == ["pw"]
    assert line["feature"]["kind"] == "line"
    np.testing.assert_allclose(line["feature"]["direction"], [0.0, 1.0, 0.0])
    assert line["feature"]["length"] == pytest.approx(0.2)  # 20 cm
    assert hold_ow == {"variables": ["ow"], "feature": {"kind": "hold"}}
    assert hold_swivel == {"variables": ["swivel"], "feature": {"kind": "hold"}}


def test_explicit_action(task: Task) -> None:
    turn = task.actions[2]
    assert turn["kind"] == "explicit" and "goal" not in turn
    first, second = turn["segments"]
    assert first["space"] == "hat" and first["duration"] == 1.5
    about, reach = first["primitives"]
    assert about == {
        "variables": ["shoulder_frame"],
        "kind": "path",
        "feature": {"kind": "about", "axis": "-r", "angle": pytest.approx(0.5236, abs=1e-4)},
    }
    assert reach["kind"] == "goal" and reach["variables"] == ["elbow", "ow"]
    assert reach["goal"]["elbow"] == pytest.approx(math.radians(100))
    np.testing.assert_allclose(reach["goal"]["ow"], np.eye(3), atol=1e-12)
    assert second["space"] == "cpsa" and second["duration"] is None
    hold, swivel = second["primitives"]
    assert hold == {"variables": ["pw", "ow"], "kind": "hold"}
    assert swivel["goal"] == {"swivel": pytest.approx(0.5236, abs=1e-4)}  # 30 deg


def test_start_state_and_base_axis() -> None:
    text = f"""robot "{ROBOT_FROM_TESTS}"
start Pw [0.2, -0.2, 0.1]  Ow rpy(0, 0, 0)  θsw 45 deg
task t {{ action a {{ path Os about z 10 deg, θe hold }} }}
"""
    task = parse_here(text)
    assert task.start is not None
    state = task.start["state"]
    assert list(state) == ["pw", "ow", "swivel"]
    np.testing.assert_allclose(state["pw"], [0.2, -0.2, 0.1])
    np.testing.assert_allclose(state["ow"], np.eye(3))
    assert state["swivel"] == pytest.approx(math.pi / 4)
    assert task.init is None and task.goal is None and task.scene == []
    about = task.actions[0]["path"]["items"][0]["feature"]
    np.testing.assert_allclose(about["axis"], [0.0, 0.0, 1.0])
    assert about["angle"] == pytest.approx(math.radians(10))
    assert task.actions[0]["path"]["space"] == "hat"


def test_to_dict_and_repr(task: Task) -> None:
    d = task.to_dict()
    assert list(d) == ["name", "robot", "start", "scene", "settings", "init", "goal", "actions"]
    assert same(d["actions"], task.actions) and same(d["scene"], task.scene)
    assert d["robot"] == task.robot
    assert repr(task) == f"Task(name='push', robot={task.robot!r}, actions=3)"


def test_data_is_a_copy(task: Task) -> None:
    start = task.start
    assert start is not None
    start["joints"][:] = 1.0
    assert task.start is not None and task.start["joints"][0] == 0.0
    with pytest.raises(AttributeError):
        task.name = "other"  # type: ignore[misc]


def test_source_and_path(task: Task) -> None:
    assert task.source == VALID
    assert task.path == str(TESTS_DIR / "task.a2ml")
    assert a2ml.parse(VALID.replace(ROBOT_FROM_TESTS, str(ROBOT))).path is None


def test_equality_ignores_layout(task: Task) -> None:
    reformatted = parse_here("# a comment\n" + VALID.replace("  ", " "))
    assert reformatted == task
    assert parse_here(VALID.replace("seed 7", "seed 8")) != task
    assert task != "push"
    with pytest.raises(TypeError):
        hash(task)


def test_load(tmp_path: Path) -> None:
    folder = tmp_path / "tasks"
    folder.mkdir()
    file = folder / "push.a2ml"
    relative = os.path.relpath(ROBOT, folder)
    file.write_text(f'robot "{relative}"\n' + BODY, encoding="utf-8")
    task = a2ml.load(file)
    # The robot path is taken relative to the file, not the working directory.
    assert task.robot == str(folder / relative)
    assert Path(task.robot).resolve() == ROBOT
    assert task.path == str(file) and task.source.endswith(BODY)
    unanchored = {**task.to_dict(), "robot": None}
    assert same(unanchored, {**parse_here(VALID).to_dict(), "robot": None})
    assert a2ml.load(str(file)) == task


def test_robot_relative_to_working_directory(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(TESTS_DIR)
    task = a2ml.parse(VALID)
    assert task.robot == ROBOT_FROM_TESTS
    monkeypatch.chdir(TESTS_DIR.parent)
    with pytest.raises(ParseError, match="robot file not found"):
        a2ml.parse(VALID)


def test_pickle_round_trip(task: Task, tmp_path: Path) -> None:
    copy = pickle.loads(pickle.dumps(task))
    assert isinstance(copy, Task) and copy == task
    assert (copy.source, copy.path) == (task.source, task.path)
    assert same(copy.to_dict(), task.to_dict())
    file = tmp_path / "push.a2ml"
    file.write_text(f'robot "{ROBOT}"\n' + BODY, encoding="utf-8")
    loaded = a2ml.load(file)
    assert pickle.loads(pickle.dumps(loaded)).path == str(file)


def test_parse_error_located() -> None:
    text = f'robot "{ROBOT}"\ntask t {{\n  action a {{ goal θs = 30 deg }}\n}}\n'
    with pytest.raises(ParseError) as info:
        a2ml.parse(text)
    e = info.value
    assert isinstance(e, A2mlError)
    assert (e.line, e.column) == (3, 19)
    assert e.message == "unknown state variable `θs`"
    assert e.errors == [(3, 19, "unknown state variable `θs`")]
    assert e.path is None
    assert str(e) == (
        "error: unknown state variable `θs`\n"
        " --> <input>:3:19\n"
        "  |\n"
        "3 |   action a { goal θs = 30 deg }\n"
        "  |                   ^^\n"
        "  = help: did you mean `θsw`?"
    )


def test_syntax_error_located() -> None:
    text = f'robot "{ROBOT}"\ntask t {{\n  action a {{ goal Pw = [0.1, 0.2 }}\n}}\n'
    with pytest.raises(ParseError) as info:
        a2ml.parse(text, "broken.a2ml")
    e = info.value
    assert (e.line, e.column) == (3, 24)
    assert e.message == "expected a value (number, vector or rotation)"
    assert e.errors == [(3, 24, e.message)]
    assert e.path == "broken.a2ml"
    assert str(e) == (
        "error: expected a value (number, vector or rotation)\n"
        " --> broken.a2ml:3:24\n"
        "  |\n"
        "3 |   action a { goal Pw = [0.1, 0.2 }\n"
        "  |                        ^"
    )


def test_every_error_listed() -> None:
    bad = """\
robot "nothere.urdf"
settings { rat 100 Hz }
task t {
  action a {
    goal θs = 30 deg
    path Pw line [0, 0, 0] 0.1 m
  }
}
"""
    with pytest.raises(ParseError) as info:
        parse_here(bad)
    e = info.value
    assert e.errors == [
        (1, 8, f"robot file not found: {TESTS_DIR / 'nothere.urdf'}"),
        (2, 12, "unknown setting `rat` (rate, solver, seed, transition, frame, acceleration)"),
        (5, 10, "unknown state variable `θs`"),
        (6, 18, "the line direction must not be zero"),
    ]
    assert (e.line, e.column, e.message) == e.errors[0]
    rendered = str(e)
    assert rendered.endswith("\n\n4 errors")
    for line, column, message in e.errors:
        assert f"error: {message}\n --> {TESTS_DIR / 'task.a2ml'}:{line}:{column}\n" in rendered
    assert "= help: did you mean `rate`?" in rendered


def test_parse_error_pickles() -> None:
    with pytest.raises(ParseError) as info:
        a2ml.parse("task t {}")
    e = pickle.loads(pickle.dumps(info.value))
    assert isinstance(e, ParseError)
    assert (e.line, e.column, e.message) == (info.value.line, info.value.column, info.value.message)
    assert e.errors == info.value.errors and str(e) == str(info.value)


def test_load_missing_file(tmp_path: Path) -> None:
    missing = tmp_path / "nope.a2ml"
    with pytest.raises(FileNotFoundError) as info:
        a2ml.load(missing)
    assert info.value.filename == str(missing)
    assert not isinstance(info.value, A2mlError)


def test_load_a_folder_is_an_os_error(tmp_path: Path) -> None:
    with pytest.raises(OSError):
        a2ml.load(tmp_path)


def test_load_invalid_file(tmp_path: Path) -> None:
    file = tmp_path / "bad.a2ml"
    file.write_text(f'robot "{ROBOT}"\nsettings {{ rate 100 Hz }}\n', encoding="utf-8")
    with pytest.raises(ParseError) as info:
        a2ml.load(file)
    assert info.value.path == str(file)
    assert info.value.message == "the file has no `task`"
    assert (info.value.line, info.value.column) == (1, 1)
