"""One spelling per enum: every enum value Python hands out (segment reports,
their dicts, warnings, the decomposition, the task's actions, compare records)
is among the values docs/cli.md documents, and the same as the plan's JSON and
its MCAP segment messages say; warnings filter by kind, action and segment."""

from __future__ import annotations

import json
import pickle
import re
from pathlib import Path
from typing import Any, Dict, List

import pytest
from mcap.reader import make_reader

import a2ml
from a2ml import Plan

ROOT = Path(__file__).resolve().parent / ".." / ".."
EXAMPLES = ROOT / "examples"
# Between them: both spaces, every pattern and variable, a fallback and warnings.
NAMES = [
    "construct_path_line",
    "construct_start_state_hat",
    "construct_explicit_segments",
    "type_iv_forward_bar",
    "construct_goal_priority",
]

SEGMENT_ENUMS = {
    "action_type": "action type",
    "space": "space",
    "pattern": "segment pattern",
    "solver": "solver",
    "fallback": "fallback",
}


def documented() -> Dict[str, List[str]]:
    """The "Enum values" table of docs/cli.md."""
    text = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    section = text.split("## Enum values", 1)[1]
    table: Dict[str, List[str]] = {}
    rows = section.split("| enum |", 1)[1].splitlines()[2:]
    for row in rows:
        cells = [c.strip() for c in row.split("|")]
        if len(cells) < 4:
            break
        table[cells[1]] = re.findall(r"`([^`]+)`", cells[2])
    return table


DOCS = documented()


@pytest.fixture(scope="module")
def plans() -> Dict[str, Plan]:
    return {name: a2ml.plan(EXAMPLES / f"{name}.a2ml") for name in NAMES}


def segment_values(record: Dict[str, Any]) -> List[tuple[str, str]]:
    """(enum, value) of a segment record, each checked against the docs."""
    values = [
        (what, record[field])
        for field, what in SEGMENT_ENUMS.items()
        if record.get(field) is not None
    ]
    values += [("variable", v) for v in record["focus"]]
    for errors in (record["errors"], record["path_errors"]):
        names = errors.keys() if isinstance(errors, dict) else [e["variable"] for e in errors]
        values += [("variable", v) for v in names]
    for what, value in values:
        assert value in DOCS[what], f"{what} {value!r} is not in docs/cli.md"
    return values


def test_the_docs_list_the_enums() -> None:
    assert DOCS["space"] == ["cpsa", "hat"]
    assert DOCS["variable"] == ["pw", "ow", "swivel", "shoulder_frame", "elbow"]
    assert DOCS["action type"] == ["i", "ii", "iii", "iv", "v", "vi", "vii"]
    for values in DOCS.values():
        assert all(re.fullmatch(r"[a-z][a-z0-9_]*", v) for v in values), values


def test_python_json_and_mcap_spell_every_value_alike(plans: Dict[str, Plan], tmp_path: Path) -> None:
    seen: set[tuple[str, str]] = set()
    for name, plan in plans.items():
        plan.to_json(tmp_path / f"{name}.json")
        plan.write_mcap(tmp_path / f"{name}.mcap")
        doc = json.loads((tmp_path / f"{name}.json").read_text(encoding="utf-8"))
        with (tmp_path / f"{name}.mcap").open("rb") as f:
            messages = [
                json.loads(message.data)
                for _, channel, message in make_reader(f).iter_messages(topics=["/a2ml/segments"])
            ]
        assert len(messages) == len(doc["segments"]) == len(plan.segments)
        for report, from_json, message in zip(plan.segments, doc["segments"], messages):
            python = segment_values(report.to_dict())
            assert python == segment_values(from_json) == segment_values(message), name
            for field in SEGMENT_ENUMS:
                assert getattr(report, field) == from_json[field]
            assert list(report.errors) == [e["variable"] for e in from_json["errors"]]
            assert all(report.errors[v].variable == v for v in report.errors)
            seen.update(python)
        assert [w._asdict() for w in plan.warnings] == doc["warnings"]
        for w in plan.warnings:
            assert w.kind in DOCS["warning kind"]
            assert str(w) == w.message
    for what in ("space", "segment pattern", "variable"):
        for value in DOCS[what]:
            assert (what, value) in seen, f"no example shows {what} {value}"


def test_warnings_filter_by_kind_action_and_segment(plans: Dict[str, Plan]) -> None:
    plan = plans["construct_goal_priority"]
    blends = [w for w in plan.warnings if w.kind == "blend_shortened"]
    assert blends, plan.warnings
    for w in blends:
        assert w.action is not None and w.segment is not None
        assert f"action `{w.action}`, segment {w.segment + 1}:" in w.message
        assert any(s.action == w.action and s.segment == w.segment for s in plan.segments)
    again = pickle.loads(pickle.dumps(plan))
    assert again.warnings == plan.warnings


def test_decomposition_task_and_compare_use_the_same_spellings() -> None:
    task = a2ml.load(EXAMPLES / "construct_start_state_hat.a2ml")
    d = a2ml.decompose(task)
    for action in d["actions"]:
        if action["type"] is not None:
            assert action["type"] in DOCS["action type"]
        for key in ("goal_space", "secondary_goal_space", "path_space"):
            assert action[key] is None or action[key] in DOCS["space"]
        for segment in action["segments"]:
            assert segment["space"] in DOCS["space"]
            assert segment["pattern"] in DOCS["segment pattern"]
            assert segment["solver"] in DOCS["solver"]
            assert set(segment["relaxed"]) <= set(DOCS["variable"])
            for p in segment["primitives"]:
                assert set(p["variables"]) <= set(DOCS["variable"])
    assert task.settings["solver"] in DOCS["solver"]
    records = a2ml.compare(EXAMPLES / "construct_path_line.a2ml", solvers=["qp"])
    keys = {k for r in records for k in r if k.startswith("error_")}
    assert keys and keys <= {f"error_{v}" for v in DOCS["variable"]}


def test_a_corrupt_pickle_state_raises_value_error(plans: Dict[str, Plan]) -> None:
    plan = plans["construct_path_line"]
    rebuild, (robot, task, text, timings) = plan.__reduce__()
    assert rebuild(robot, task, text, timings).segments == plan.segments
    with pytest.raises(ValueError, match="invalid plan: unknown variant `CPSA`"):
        rebuild(robot, task, text.replace('"cpsa"', '"CPSA"'), timings)
    with pytest.raises(ValueError, match="timings for"):
        rebuild(robot, task, text, timings[:-1])
