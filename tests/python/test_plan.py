"""The Python API of planning: a2ml.plan on examples/construct_path_line.a2ml
(from a path and from a Task), the arrays and reports of a Plan, the errors,
determinism and pickling, and the writers: the CSV read back with numpy, the
JSON with json, and the MCAP with the independent reader of the ``mcap``
package (channels, schemas, counts, log times, payloads, attachments), every
message validated with jsonschema against its embedded schema and the Foxglove
ones against Foxglove's official schemas."""

from __future__ import annotations

import json
import math
import os
import pickle
from collections import defaultdict
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import jsonschema
import numpy as np
import pytest
from mcap.reader import make_reader

import a2ml
from a2ml import Plan, PlanError, SegmentReport, Task

TESTS_DIR = Path(__file__).resolve().parent
EXAMPLES = TESTS_DIR / ".." / ".." / "examples"
EXAMPLE = EXAMPLES / "construct_path_line.a2ml"

# The topics the project requires of every MCAP file, with their schemas.
SCHEMAS = {
    "/joint_states": "a2ml.JointState",
    "/tf": "foxglove.FrameTransforms",
    "/scene": "foxglove.SceneUpdate",
    "/wrist_path": "foxglove.SceneUpdate",
    "/a2ml/state": "a2ml.State",
    "/a2ml/segments": "a2ml.Segment",
    "/arm_capsules": "foxglove.SceneUpdate",
    "/robot_description": "std_msgs/String",
}

# Foxglove's own JSON Schemas (vendored from foxglove/schemas, see tests/data/README.md).
FOXGLOVE_SCHEMAS = TESTS_DIR / ".." / "data" / "foxglove_schemas"


@pytest.fixture(scope="module")
def plan() -> Plan:
    return a2ml.plan(EXAMPLE)


def assert_grid(t: np.ndarray[Any, np.dtype[np.float64]], rate: float) -> None:
    """Times from 0 in steps of 1 / rate, strictly increasing, and the plan's
    end as the last sample (a shorter last step)."""
    assert t[0] == 0.0
    steps = np.diff(t)
    assert np.all(steps > 0.0)
    np.testing.assert_allclose(steps[:-1], 1.0 / rate, rtol=0.0, atol=1e-9)
    assert steps[-1] <= 1.0 / rate + 1e-9
    np.testing.assert_allclose(t[:-1], np.arange(len(t) - 1) / rate, rtol=0.0, atol=1e-9)


def assert_same_plan(a: Plan, b: Plan) -> None:
    """Bit-identical arrays and equal reports, QP timings aside."""
    for name in ("t", "q", "qd", "wrist_reference"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.joint_names == b.joint_names
    assert a.rate == b.rate
    assert a.warnings == b.warnings
    assert a.reached == b.reached
    assert len(a.segments) == len(b.segments)
    for x, y in zip(a.segments, b.segments):
        dx, dy = x.to_dict(), y.to_dict()
        del dx["qp"], dy["qp"]
        assert dx == dy


def test_plan_from_a_path(plan: Plan) -> None:
    task = a2ml.load(EXAMPLE)
    n = len(plan.t)
    assert n > 1
    assert plan.t.dtype == np.float64 and plan.t.shape == (n,)
    assert plan.q.dtype == np.float64 and plan.q.shape == (n, 7)
    assert plan.qd.dtype == np.float64 and plan.qd.shape == (n, 7)
    assert plan.rate == task.settings["rate"] == 100.0
    assert_grid(plan.t, plan.rate)
    assert np.all(np.isfinite(plan.q)) and np.all(np.isfinite(plan.qd))
    assert plan.reached
    assert plan.warnings == []
    assert plan.task == task
    assert plan.task.source == EXAMPLE.read_text(encoding="utf-8")
    assert plan.robot.name == a2ml.Robot.from_urdf(task.robot).name
    assert plan.joint_names == plan.robot.joint_names
    assert plan.safety_distance > 0.0
    assert "Plan(task='lines'" in repr(plan)


def test_q_within_the_joint_limits(plan: Plan) -> None:
    robot = plan.robot
    assert np.all(plan.q >= robot.lower - 1e-9)
    assert np.all(plan.q <= robot.upper + 1e-9)
    assert all(s.limit_margin >= -1e-9 for s in plan.segments)


def test_the_plan_starts_at_the_task_start(plan: Plan) -> None:
    start = plan.task.start
    assert start is not None
    np.testing.assert_allclose(plan.q[0], start["joints"], atol=1e-9)
    np.testing.assert_allclose(plan.qd[0], np.zeros(7), atol=1e-9)


def test_plan_from_a_task_is_the_same(plan: Plan) -> None:
    """Planning is deterministic: a Task or its path, and a second run, give
    bit-identical arrays."""
    task = a2ml.load(EXAMPLE)
    from_task = a2ml.plan(task)
    assert from_task.task is task
    assert_same_plan(from_task, plan)
    assert_same_plan(a2ml.plan(task), from_task)


def test_plan_from_parsed_text_and_path_types(plan: Plan) -> None:
    text = EXAMPLE.read_text(encoding="utf-8")
    parsed = a2ml.parse(text, EXAMPLE)
    assert_same_plan(a2ml.plan(parsed), plan)
    assert_same_plan(a2ml.plan(str(EXAMPLE)), plan)


def test_plans_run_in_threads(plan: Plan) -> None:
    """The GIL is released while planning; results do not depend on it."""
    task = a2ml.load(EXAMPLE)
    with ThreadPoolExecutor(max_workers=2) as pool:
        plans = list(pool.map(lambda _: a2ml.plan(task), range(2)))
    for p in plans:
        assert_same_plan(p, plan)


def test_segment_reports(plan: Plan) -> None:
    task = plan.task
    segments = plan.segments
    assert segments and all(isinstance(s, SegmentReport) for s in segments)
    assert [s.action for s in segments][:1] == ["slide_left"]
    names = [a["name"] for a in task.actions]
    assert {s.action for s in segments} == set(names)
    previous_start = -math.inf
    for s in segments:
        assert names[s.action_index] == s.action
        assert s.segment >= 0
        assert s.action_type in ("i", "ii", "iii", "iv", "v", "vi", "vii")
        assert s.space in ("cpsa", "hat")
        assert s.pattern in ("path", "goal", "mixed")
        assert s.solver == "qp"
        assert s.focus and set(s.focus) <= {"pw", "ow", "swivel", "shoulder_frame", "elbow"}
        assert previous_start <= s.start < s.end <= plan.t[-1] + 1.0 / plan.rate
        previous_start = s.start
        assert s.duration > 0.0 and s.settle >= 0.0
        expected = ["pw", "ow", "swivel"] if s.space == "cpsa" else ["shoulder_frame", "elbow", "ow"]
        assert list(s.errors) == expected
        for e in s.errors.values():
            assert isinstance(e, a2ml.VariableError)
            assert e.error >= 0.0 and e.within
        assert set(s.path_errors) <= set(expected)
        assert s.clearance is None or isinstance(s.clearance, a2ml.Clearance)
        assert not s.stalled and s.reached
        assert isinstance(s.qp, a2ml.QpStats) and s.rrt is None
        assert s.qp.steps > 0 and 0 <= s.qp.clarabel_steps <= s.qp.steps
        assert s.qp.worst_step_time >= s.qp.mean_step_time > 0.0
        d = s.to_dict()
        assert list(d)[:3] == ["action", "action_index", "segment"]
        assert d["errors"] == s.errors and d["qp"] == s.qp
    first = segments[0]
    assert first.action_type == "i" and first.focus[0] == "pw"
    assert repr(first).startswith("SegmentReport(action='slide_left', segment=0")
    rise = [s for s in segments if s.action == "rise_towards_elbow_goal"]
    assert rise and all(s.action_type == "iv" for s in rise)


def test_wrist_reference(plan: Plan) -> None:
    ref = plan.wrist_reference
    assert ref.dtype == np.float64 and ref.ndim == 2 and ref.shape[1] == 4
    assert len(ref) > 0 and np.all(np.isfinite(ref))
    assert ref[0, 0] == 0.0 and np.all(np.diff(ref[:, 0]) >= 0.0)
    # The first action slides the wrist 12 cm along +y with x and z held.
    pw0 = plan.robot.centers(plan.q[0])["wrist"]
    first = plan.segments[0]
    during = ref[ref[:, 0] <= first.start + first.duration]
    np.testing.assert_allclose(during[0, 1:], pw0, atol=1e-9)
    np.testing.assert_allclose(during[-1, 1:], pw0 + [0.0, 0.12, 0.0], atol=1e-6)


def test_rate_and_seed() -> None:
    slow = a2ml.plan(EXAMPLE, rate=25.0, seed=3)
    assert slow.rate == 25.0
    assert_grid(slow.t, 25.0)
    assert slow.reached


def test_rates_within_the_limits_and_a_lower_acceleration_limit() -> None:
    full = a2ml.plan(EXAMPLE)
    quarter = a2ml.plan(EXAMPLE, acceleration_scale=0.25, time_limit=600.0)
    for p in (full, quarter):
        assert p.reached
        for s in p.segments:
            assert s.limits_kept
            assert 0.0 < s.peak_velocity_ratio <= 1.0
            assert 0.0 < s.peak_acceleration_ratio <= 1.0
            assert s.speed_peaks >= 1
            assert s.joint_jerk > 0.0 and s.wrist_jerk > 0.0
            assert s.slowed_down >= 1.0
    with pytest.raises(ValueError):
        a2ml.plan(EXAMPLE, acceleration_scale=-1.0)


def test_auto_runs_the_qp() -> None:
    task = a2ml.load(EXAMPLE)
    assert_same_plan(a2ml.plan(task, solver="qp"), a2ml.plan(task, solver="auto"))


def test_solver_overrides_the_task_and_its_actions() -> None:
    """By default each action keeps its own solver (here `qp` for the task,
    `rrt` for one action); `solver=` replaces every one."""
    path = EXAMPLES / "construct_settings.a2ml"
    own = a2ml.plan(path)
    assert [s.solver for s in own.segments] == ["qp", "rrt"]
    rrt = own.segments[1].rrt
    assert rrt is not None and rrt.collision_checks > 0
    p = a2ml.plan(path, solver="qp")
    assert p.rate == 200.0
    assert [s.solver for s in p.segments] == ["qp"] * len(p.segments)


def test_unavailable_solver_raises() -> None:
    with pytest.raises(PlanError, match="not available yet") as info:
        a2ml.plan(EXAMPLE, solver="hamp")
    assert isinstance(info.value, a2ml.A2mlError)
    assert "slide_left" in str(info.value)


def test_unknown_solver_raises() -> None:
    with pytest.raises(ValueError, match=r"unknown solver `fast` \(expected one of: auto, qp, rrt, "):
        a2ml.plan(EXAMPLE, solver="fast")  # type: ignore[arg-type]


@pytest.mark.parametrize("rate", [0.0, -10.0, math.nan, math.inf])
def test_invalid_rate_raises(rate: float) -> None:
    with pytest.raises(ValueError, match="invalid output rate"):
        a2ml.plan(EXAMPLE, rate=rate)


def test_bad_arguments_raise(tmp_path: Path) -> None:
    with pytest.raises(TypeError, match="a2ml.Task or a path"):
        a2ml.plan(42)  # type: ignore[arg-type]
    with pytest.raises(FileNotFoundError):
        a2ml.plan(tmp_path / "missing.a2ml")
    bad = tmp_path / "bad.a2ml"
    bad.write_text("task broken {", encoding="utf-8")
    with pytest.raises(a2ml.ParseError):
        a2ml.plan(bad)


def test_a_bad_robot_file_raises_urdf_error(tmp_path: Path) -> None:
    # The parser checks that the file exists; what it holds is checked when planning.
    urdf = tmp_path / "not_an_arm.urdf"
    urdf.write_text('<robot name="stick"><link name="a"/></robot>', encoding="utf-8")
    text = EXAMPLE.read_text(encoding="utf-8").replace(
        "../robots/coman_right_arm.urdf", urdf.as_posix()
    )
    with pytest.raises(a2ml.UrdfError):
        a2ml.plan(a2ml.parse(text))


def test_decompose_errors_keep_their_class() -> None:
    text = EXAMPLE.read_text(encoding="utf-8")
    no_start = "\n".join(line for line in text.splitlines() if not line.startswith("start"))
    with pytest.raises(a2ml.DecomposeError):
        a2ml.plan(a2ml.parse(no_start, EXAMPLE))


def test_a_given_robot_is_used(plan: Plan) -> None:
    robot = plan.robot
    again = a2ml.plan(plan.task, robot=robot)
    assert again.robot is robot
    assert_same_plan(again, plan)


def test_pickle_round_trip(plan: Plan) -> None:
    back = pickle.loads(pickle.dumps(plan))
    assert isinstance(back, Plan)
    assert_same_plan(back, plan)
    assert back.segments == plan.segments  # QP timings included
    assert back.safety_distance == plan.safety_distance
    assert back.task == plan.task and back.task.source == plan.task.source
    assert back.robot.name == plan.robot.name
    report = plan.segments[-1]
    assert pickle.loads(pickle.dumps(report)) == report
    assert report != plan.segments[0]


def test_an_unpickled_plan_writes_the_same_files(plan: Plan, tmp_path: Path) -> None:
    back = pickle.loads(pickle.dumps(plan))
    plan.to_json(tmp_path / "a.json")
    back.to_json(tmp_path / "b.json")
    assert (tmp_path / "a.json").read_bytes() == (tmp_path / "b.json").read_bytes()


def test_csv_round_trip(plan: Plan, tmp_path: Path) -> None:
    path = tmp_path / "plan.csv"
    plan.to_csv(path)
    with path.open(encoding="utf-8") as f:
        header = f.readline().strip().split(",")
    names = plan.joint_names
    assert header[:15] == ["t"] + [f"{n}_pos" for n in names] + [f"{n}_vel" for n in names]
    # Then the references (docs/cli.md), a field empty where a value is undefined.
    assert header[15] == "ref_segment" and header[28] == "ref_elbow"
    table = np.loadtxt(path, delimiter=",", skiprows=1, usecols=range(15))
    assert table.shape == (len(plan.t), 15)
    # Numbers are written in a form that reads back exactly.
    np.testing.assert_array_equal(table[:, 0], plan.t)
    np.testing.assert_array_equal(table[:, 1:8], plan.q)
    np.testing.assert_array_equal(table[:, 8:15], plan.qd)


def test_json(plan: Plan, tmp_path: Path) -> None:
    path = tmp_path / "plan.json"
    plan.to_json(os.fspath(path))
    doc = json.loads(path.read_text(encoding="utf-8"))
    assert doc["robot"] == plan.robot.name
    assert doc["rate"] == plan.rate
    assert doc["joint_names"] == plan.joint_names
    assert len(doc["segments"]) == len(plan.segments)
    assert doc["warnings"] == [w._asdict() for w in plan.warnings]


def test_a_failed_write_leaves_no_file(plan: Plan, tmp_path: Path) -> None:
    target = tmp_path / "missing" / "out.mcap"
    with pytest.raises(OSError):
        plan.write_mcap(target)
    assert not target.exists()
    assert list(tmp_path.iterdir()) == []


# --- MCAP, read back with the mcap package's reader -------------------------


class Recording:
    """Everything in an MCAP file, read once with the independent reader."""

    def __init__(self, path: Path) -> None:
        self.messages: dict[str, list[tuple[int, Any]]] = defaultdict(list)
        self.schemas: dict[str, tuple[str, str, Any]] = {}
        self.encodings: dict[str, str] = {}
        with path.open("rb") as f:
            reader = make_reader(f)
            summary = reader.get_summary()
            assert summary is not None
            self.summary = summary
            for schema, channel, message in reader.iter_messages(log_time_order=False):
                assert schema is not None
                topic = channel.topic
                self.schemas[topic] = (schema.name, schema.encoding, json.loads(schema.data))
                self.encodings[topic] = channel.message_encoding
                self.messages[topic].append((message.log_time, json.loads(message.data)))
            f.seek(0)
            self.attachments = {a.name: a for a in make_reader(f).iter_attachments()}
            f.seek(0)
            self.metadata = {m.name: m.metadata for m in make_reader(f).iter_metadata()}


@pytest.fixture(scope="module")
def recording(plan: Plan, tmp_path_factory: pytest.TempPathFactory) -> Recording:
    path = tmp_path_factory.mktemp("mcap") / "out.mcap"
    plan.write_mcap(path)
    return Recording(path)


def test_mcap_channels_and_schemas(recording: Recording) -> None:
    topics = {c.topic for c in recording.summary.channels.values()}
    assert set(SCHEMAS) <= topics
    for topic, name in SCHEMAS.items():
        schema_name, encoding, body = recording.schemas[topic]
        assert schema_name == name, topic
        assert encoding == "jsonschema"
        assert isinstance(body, dict) and body
        assert recording.encodings[topic] == "json"
    for channel in recording.summary.channels.values():
        assert channel.message_encoding == "json"


def test_mcap_message_counts(plan: Plan, recording: Recording) -> None:
    samples = len(plan.t)
    counts = {topic: len(ms) for topic, ms in recording.messages.items()}
    assert counts["/joint_states"] == samples
    assert counts["/tf"] == samples
    assert counts["/a2ml/state"] == samples
    assert counts["/a2ml/segments"] == len(plan.segments)
    # Sent once: what does not change over the plan (the capsules ride on /tf).
    for topic in ["/scene", "/wrist_path", "/arm_capsules", "/robot_description"]:
        assert counts[topic] == 1, topic
    statistics = recording.summary.statistics
    assert statistics is not None
    assert statistics.message_count == sum(counts.values())


def test_mcap_log_times(plan: Plan, recording: Recording) -> None:
    for topic, messages in recording.messages.items():
        times = [t for t, _ in messages]
        assert times == sorted(times), topic
    joint_times = np.array([t for t, _ in recording.messages["/joint_states"]])
    np.testing.assert_array_equal(joint_times, np.round(plan.t * 1e9).astype(np.int64))
    assert np.all(np.diff(joint_times) > 0)
    segment_times = [t for t, _ in recording.messages["/a2ml/segments"]]
    assert segment_times == [round(s.start * 1e9) for s in plan.segments]


def test_mcap_payloads(plan: Plan, recording: Recording) -> None:
    states = [m for _, m in recording.messages["/joint_states"]]
    assert all(m["name"] == plan.joint_names for m in states)
    np.testing.assert_array_equal([m["position"] for m in states], plan.q)
    np.testing.assert_array_equal([m["velocity"] for m in states], plan.qd)
    segments = [m for _, m in recording.messages["/a2ml/segments"]]
    assert [(m["action"], m["segment"]) for m in segments] == [
        (s.action, s.segment) for s in plan.segments
    ]
    for _, tf in recording.messages["/tf"]:
        assert tf["transforms"]
    assert recording.messages["/scene"][0][1]["entities"] is not None


def test_mcap_attachments_and_metadata(plan: Plan, recording: Recording) -> None:
    task = plan.task
    source = recording.attachments[f"{task.name}.a2ml"]
    assert source.data == EXAMPLE.read_bytes()
    assert source.media_type == "text/plain"
    urdf = recording.attachments[f"{plan.robot.name}.urdf"]
    assert urdf.data == Path(task.robot).read_bytes()
    assert len(recording.attachments) == 2
    metadata = recording.metadata["a2ml"]
    assert metadata["task"] == task.name
    assert metadata["robot"] == plan.robot.name
    assert metadata["reached"] == "true"


def test_mcap_of_a_parsed_task_attaches_its_text(tmp_path: Path) -> None:
    text = EXAMPLE.read_text(encoding="utf-8") + "\n# parsed, not loaded\n"
    p = a2ml.plan(a2ml.parse(text, EXAMPLE), rate=20.0)
    path = tmp_path / "parsed.mcap"
    p.write_mcap(path)
    recording = Recording(path)
    assert recording.attachments["lines.a2ml"].data == text.encode("utf-8")
    assert len(recording.messages["/joint_states"]) == len(p.t)


def test_auto_gives_a_goal_among_obstacles_to_the_rrt() -> None:
    plan = a2ml.plan(EXAMPLES / "construct_scene.a2ml")
    (report,) = plan.segments
    assert report.solver == "rrt" and plan.reached
    assert isinstance(report.rrt, a2ml.RrtStats)
    assert report.rrt.nodes >= 2 and report.rrt.collision_checks > 0
    assert report.to_dict()["rrt"] == report.rrt
    again = pickle.loads(pickle.dumps(report))
    assert again == report and again.rrt == report.rrt


def test_auto_goes_on_to_the_rrt_when_the_qp_stalls_on_a_hard_path() -> None:
    """Paper §6.2: the QP keeps the wrist's line and the forward bar stops it
    there, short of the goal; the constrained RRT reaches the goal on it."""
    path = EXAMPLES / "type_iv_forward_bar.a2ml"
    qp = a2ml.plan(path, solver="qp").segments[0]
    assert qp.hard_path and qp.path_kept and qp.fallback is None
    assert qp.stalled and not qp.reached
    assert qp.path_errors["pw"].error < 1e-3
    auto = a2ml.plan(path, solver="auto")
    segment = auto.segments[0]
    assert (segment.solver, segment.fallback) == ("rrt", "qp_stalled")
    assert segment.path_kept and segment.reached and auto.reached
    assert segment.path_errors["pw"].error < 1e-9
    assert segment.to_dict()["fallback"] == "qp_stalled"
    assert pickle.loads(pickle.dumps(segment)) == segment


def test_mcap_foxglove_messages_pass_the_official_schemas(recording: Recording) -> None:
    official = {
        name: json.loads((FOXGLOVE_SCHEMAS / f"{name}.json").read_text(encoding="utf-8"))
        for name in ["SceneUpdate", "FrameTransforms"]
    }
    checked = 0
    for topic, (schema_name, _, _) in recording.schemas.items():
        if not schema_name.startswith("foxglove."):
            continue
        schema = official[schema_name.removeprefix("foxglove.")]
        validator = jsonschema.Draft202012Validator(schema)
        for _, message in recording.messages[topic]:
            validator.validate(message)
            checked += 1
    assert checked >= len(recording.messages["/tf"]) + 3


def test_mcap_own_messages_pass_their_embedded_schemas(recording: Recording) -> None:
    for topic, (_, _, schema) in recording.schemas.items():
        validator = jsonschema.Draft202012Validator(schema)
        for _, message in recording.messages[topic]:
            validator.validate(message)


def test_mcap_robot_description_and_capsules(plan: Plan, recording: Recording) -> None:
    [(_, description)] = recording.messages["/robot_description"]
    assert description["data"] == Path(plan.task.robot).read_text(encoding="utf-8")
    assert "<visual" in description["data"]
    [(_, capsules)] = recording.messages["/arm_capsules"]
    frames = {t["child_frame_id"] for t in recording.messages["/tf"][0][1]["transforms"]}
    for entity in capsules["entities"]:
        assert entity["frame_locked"] is True
        assert entity["frame_id"] in frames, entity["frame_id"]


def test_plan_files_are_byte_for_byte_reproducible(tmp_path: Path) -> None:
    """Two plans of one task write the same bytes: the files hold no wall-clock
    times, which stay in the report objects."""
    first, second = a2ml.plan(EXAMPLE), a2ml.plan(EXAMPLE)
    for name, p in (("first", first), ("second", second)):
        p.write_mcap(tmp_path / f"{name}.mcap")
        p.to_csv(tmp_path / f"{name}.csv")
        p.to_json(tmp_path / f"{name}.json")
    for suffix in ("mcap", "csv", "json"):
        a = (tmp_path / f"first.{suffix}").read_bytes()
        assert a == (tmp_path / f"second.{suffix}").read_bytes(), suffix
    assert all(s.qp.mean_step_time > 0.0 for s in first.segments)
    assert b"step_time" not in (tmp_path / "first.json").read_bytes()
