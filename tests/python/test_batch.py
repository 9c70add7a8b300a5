"""Many tasks at once: tasks generated with Task.with_goal, a2ml.plan_many
(input order, errors as values, equal to one-at-a-time planning), the Parquet
table of a plan read back with pyarrow, the task's robot loaded with its base
and tip, and the cluster helpers on a Dask LocalCluster (two worker
processes) and a local Ray instance, compared with serial planning."""

from __future__ import annotations

import pickle
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import a2ml
from a2ml import ParseError, Plan, Task

TESTS_DIR = Path(__file__).resolve().parent
ROOT = TESTS_DIR / ".." / ".."
SCENE = ROOT / "examples" / "construct_scene.a2ml"
BAXTER = ROOT / "tests" / "data" / "tasks" / "baxter_left_reach.a2ml"

# Targets of the scene example's reach, around its first goal.
TARGETS = [[0.22, -0.06, -0.05], [0.24, -0.08, -0.05], [0.20, -0.08, -0.03]]


def reaches() -> list[Task]:
    task = a2ml.load(SCENE)
    return [task.with_goal("reach_over_table", pw=p) for p in TARGETS]


def untimed(segment: a2ml.SegmentReport) -> dict[str, Any]:
    """A report without its wall-clock timings (QP step and RRT times)."""
    d = segment.to_dict()
    qp, rrt = d.pop("qp"), d.pop("rrt")
    d["qp_steps"] = (qp.steps, qp.clarabel_steps)
    d["rrt"] = None if rrt is None else (rrt.samples, rrt.nodes, rrt.collision_checks)
    return d


def same_plan(a: Plan, b: Plan) -> None:
    assert np.array_equal(a.t, b.t)
    assert np.array_equal(a.q, b.q)
    assert np.array_equal(a.qd, b.qd)
    assert [untimed(s) for s in a.segments] == [untimed(s) for s in b.segments]
    assert a.warnings == b.warnings


def test_with_goal_replaces_the_goal_and_keeps_the_rest() -> None:
    task = a2ml.load(SCENE)
    moved = task.with_goal("reach_over_table", pw=[0.24, -0.04, -0.05], swivel=1.0)
    goal = moved.actions[0]["goal"]["primary"]
    assert np.allclose(goal["pw"], [0.24, -0.04, -0.05], atol=0, rtol=0)
    assert goal["swivel"] == 1.0
    assert np.array_equal(goal["ow"], task.actions[0]["goal"]["primary"]["ow"])
    assert [o["name"] for o in moved.scene] == [o["name"] for o in task.scene]
    assert moved.path == task.path and moved.robot == task.robot
    assert "# The planner keeps the arm's capsules" in moved.source, "comments kept"
    assert pickle.loads(pickle.dumps(moved)) == moved
    assert moved != task


def test_with_goal_refuses_what_the_task_does_not_say() -> None:
    task = a2ml.load(SCENE)
    with pytest.raises(ValueError, match="no action `fetch`"):
        task.with_goal("fetch", pw=[0.2, 0.0, 0.0])
    with pytest.raises(ValueError, match="no goal on"):
        task.with_goal("reach_over_table", elbow=1.0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'wrist'"):
        task.with_goal("reach_over_table", wrist=[0.2, 0.0, 0.0])  # type: ignore[call-arg]
    with pytest.raises(ValueError):
        task.with_goal("reach_over_table", pw=[0.2, 0.0])
    with pytest.raises(ValueError, match="finite"):
        task.with_goal("reach_over_table", swivel=float("nan"))


def test_plan_many_equals_planning_one_at_a_time(tmp_path: Path) -> None:
    invalid = tmp_path / "invalid.a2ml"
    invalid.write_text("task {")
    tasks: list[Any] = [*reaches(), invalid, tmp_path / "nowhere.a2ml", SCENE]
    results = a2ml.plan_many(tasks, jobs=2)
    assert len(results) == len(tasks)
    for task, result in zip(tasks[:3], results[:3]):
        assert isinstance(result, Plan)
        same_plan(result, a2ml.plan(task))
    assert isinstance(results[3], ParseError)
    assert isinstance(results[4], FileNotFoundError)
    assert isinstance(results[5], Plan)
    same_plan(results[5], a2ml.plan(SCENE))
    # The same with one thread, a seed and a robot given.
    first = results[0]
    assert isinstance(first, Plan)
    robot = first.robot
    serial = a2ml.plan_many(reaches(), robot=robot, jobs=1, seed=3)
    for task, result in zip(reaches(), serial):
        assert isinstance(result, Plan)
        same_plan(result, a2ml.plan(task, robot=robot, seed=3))


def test_plan_many_takes_any_iterable_and_checks_its_options() -> None:
    assert a2ml.plan_many(iter([])) == []
    with pytest.raises(ValueError, match="jobs"):
        a2ml.plan_many([SCENE], jobs=0)
    with pytest.raises(ValueError, match="unknown solver"):
        a2ml.plan_many([SCENE], solver="fast")  # type: ignore[arg-type]
    (result,) = a2ml.plan_many([42])  # type: ignore[list-item]
    assert isinstance(result, TypeError)


def test_the_task_robot_has_its_base_and_tip() -> None:
    plan = a2ml.plan(BAXTER)
    assert (plan.robot.base_link, plan.robot.tip_link) == ("left_arm_mount", "left_wrist")
    assert plan.reached
    again = pickle.loads(pickle.dumps(plan))
    assert again.robot.base_link == "left_arm_mount"
    decomposition = a2ml.decompose(a2ml.load(BAXTER))
    assert decomposition["actions"][0]["segments"]
    (many,) = a2ml.plan_many([BAXTER])
    assert isinstance(many, Plan)
    same_plan(many, plan)
    rows = a2ml.compare(BAXTER, solvers=["qp"])
    assert rows


def test_the_parquet_table_reads_back(tmp_path: Path) -> None:
    pa = pytest.importorskip("pyarrow", reason="pyarrow reads the Parquet table back")
    pq = pytest.importorskip("pyarrow.parquet")
    plan = a2ml.plan(SCENE)
    path = tmp_path / "scene.parquet"
    plan.to_parquet(path, task_id="scene-0")
    table = pq.read_table(path)
    assert table.num_rows == len(plan.t)
    names = ["task", "action", "action_index", "segment", "t"]
    names += [f"q{j}" for j in range(1, 8)] + [f"qd{j}" for j in range(1, 8)]
    names += ["pw_x", "pw_y", "pw_z", "ow_w", "ow_x", "ow_y", "ow_z", "swivel", "clearance"]
    assert table.column_names == names
    assert set(table.column("task").to_pylist()) == {"scene-0"}
    assert np.array_equal(table.column("t").to_numpy(), plan.t)
    for j in range(7):
        assert np.array_equal(table.column(f"q{j + 1}").to_numpy(), plan.q[:, j])
        assert np.array_equal(table.column(f"qd{j + 1}").to_numpy(), plan.qd[:, j])
    clearance = table.column("clearance").to_numpy()
    assert clearance.min() >= plan.safety_distance - 1e-4
    segment_clearance = plan.segments[0].clearance
    assert segment_clearance is not None
    assert abs(clearance.min() - segment_clearance.distance) < 1e-6
    metadata = table.schema.metadata
    assert metadata[b"a2ml.robot"] == b"coman_right_arm"

    # Two robots, one schema: the tables of a batch concatenate.
    arrow = a2ml.plan(BAXTER).to_arrow(task_id="baxter")
    both = pa.concat_tables([table, arrow.cast(table.schema)])
    assert both.num_rows == table.num_rows + arrow.num_rows
    assert arrow.schema.equals(table.schema, check_metadata=False)


def test_dask_plans_a_batch_as_serial_planning() -> None:
    distributed = pytest.importorskip("dask.distributed", reason="dask[distributed] is not installed")
    import a2ml.dask

    tasks = reaches()
    serial = [a2ml.plan(t) for t in tasks]
    robot = serial[0].robot
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        bag = a2ml.dask.plan_bag([*tasks, "nowhere.a2ml"], robot=robot, npartitions=2)
        results = client.compute(bag).result()
    assert len(results) == len(tasks) + 1
    for expected, result in zip(serial, results):
        assert isinstance(result, Plan)
        same_plan(result, expected)
    assert isinstance(results[-1], FileNotFoundError)


def test_ray_plans_a_batch_as_serial_planning() -> None:
    ray = pytest.importorskip("ray", reason="ray has no wheel for this Python or is not installed")
    import a2ml.ray

    tasks = reaches()
    serial = [a2ml.plan(t) for t in tasks]
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        results = a2ml.ray.plan_remote([*tasks, "nowhere.a2ml"], robot=serial[0].robot, chunks=2)
    finally:
        ray.shutdown()
    assert len(results) == len(tasks) + 1
    for expected, result in zip(serial, results):
        assert isinstance(result, Plan)
        same_plan(result, expected)
    assert isinstance(results[-1], FileNotFoundError)
