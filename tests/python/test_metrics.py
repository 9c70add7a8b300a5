"""The Python API of the human-likeness measures: a2ml.metrics on every example
that plans (a fresh Plan.metrics() against the same plan read back from its
MCAP and CSV files), the similarity indices, Fitts and RULA Table A, the HAMP
handover planner and the errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import a2ml
import a2ml.metrics

TESTS_DIR = Path(__file__).resolve().parent
EXAMPLES = sorted((TESTS_DIR / ".." / ".." / "examples").glob("*.a2ml"))
COMAN = TESTS_DIR / ".." / ".." / "robots" / "coman_right_arm.urdf"


def test_similarity_indices_and_fitts() -> None:
    assert a2ml.metrics.similarity("ΦPO-PO", "P-ΦPO-PO") == 0.8
    assert a2ml.metrics.similarity("phiPO-PO", "ΦPO-PO") == 1.0
    assert a2ml.metrics.levenshtein("ΦPO-PO", "ΦPO") == 1
    population = [("ΦPO-PO", 0.412), ("ΦPO", 0.25), ("ΦPO-PO-ΦPO", 0.1071),
                  ("ΦPO-PO-ΦPO-PO", 0.0852), ("PO-ΦPO-PO", 0.0396)]
    simc = a2ml.metrics.connection_similarity("ΦPO-PO", "ΦPO", 0.412, population)
    assert abs(simc - 0.842) < 1e-3
    scores = a2ml.metrics.mpcsi(["ΦPO-PO", "PO"], ["ΦPO-PO", "ΦPO-PO-ΦPO"], population)
    assert scores[0] > scores[1]
    assert abs(a2ml.metrics.fitts_duration(0.1) - 0.8027) < 1e-4
    assert abs(a2ml.metrics.fitts_duration(0.3) - 1.0127) < 1e-4
    assert a2ml.metrics.rula_table_a(4, 3, 4, 2) == 6


def test_bad_arguments_raise(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="primitive"):
        a2ml.metrics.similarity("OP", "PO")
    with pytest.raises(ValueError):
        a2ml.metrics.rula_table_a(7, 1, 1, 1)
    with pytest.raises(ValueError):
        a2ml.metrics.fitts_duration(-1.0)
    with pytest.raises(TypeError):
        a2ml.metrics.analyze(3)  # type: ignore[arg-type]
    with pytest.raises(OSError):
        a2ml.metrics.analyze(tmp_path / "missing.mcap")
    bad = tmp_path / "plan.csv"
    bad.write_text("t,x\n0,1\n")
    with pytest.raises(ValueError, match="plan.csv:1"):
        a2ml.metrics.analyze(bad, a2ml.Robot.from_urdf(COMAN))


def _same(a: dict[str, object], b: dict[str, object]) -> None:
    pa, pb = a["patterns"], b["patterns"]
    assert isinstance(pa, dict) and isinstance(pb, dict)
    for phase in ("whole", "phase1", "phase2"):
        assert pa[phase]["hamp"] == pb[phase]["hamp"]
    for key in ("rula", "rula_sum"):
        ra, rb = a[key], b[key]
        assert isinstance(ra, dict) and isinstance(rb, dict)
        assert math.isclose(ra["mean"], rb["mean"], rel_tol=1e-9, abs_tol=1e-9)
        assert ra["max"] == rb["max"]
    fa, fb = a["fitts"], b["fitts"]
    assert isinstance(fa, dict) and isinstance(fb, dict)
    assert math.isclose(fa["duration"], fb["duration"], rel_tol=1e-9, abs_tol=1e-9)


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_every_example_scores_the_same_fresh_and_read_back(example: Path, tmp_path: Path) -> None:
    try:
        plan = a2ml.plan(example)
    except (a2ml.PlanError, a2ml.DecomposeError) as e:
        # A solver that does not exist yet, or a construct example without a start, leaves
        # an example without a plan to score.
        assert "not available yet" in str(e) or "has no `start`" in str(e)
        return
    fresh = plan.metrics()
    frames = fresh["frames"]
    n = len(plan.t)
    for key in ("t", "position_speed", "orientation_speed", "swivel_speed", "rula", "rula_sum"):
        assert frames[key].dtype == np.float64 and frames[key].shape == (n,)
    scored = frames["rula"][~np.isnan(frames["rula"])]
    assert np.all((scored >= 1) & (scored <= 9))
    assert len(fresh["segments"]) == len(plan.segments)

    mcap = tmp_path / "plan.mcap"
    csv = tmp_path / "plan.csv"
    plan.write_mcap(mcap)
    plan.to_csv(csv)
    from_mcap = a2ml.metrics.analyze(mcap)
    _same(fresh["whole"], from_mcap["whole"])
    for a, b in zip(fresh["segments"], from_mcap["segments"]):
        assert a["span"]["label"] == b["span"]["label"]
        _same(a, b)
    np.testing.assert_allclose(from_mcap["frames"]["position_speed"], frames["position_speed"],
                               rtol=1e-9, atol=1e-12)
    from_csv = a2ml.metrics.analyze(csv, plan.robot)
    _same(fresh["whole"], from_csv["whole"])
    assert from_csv["segments"] == []
    assert a2ml.metrics.analyze(plan)["whole"] == fresh["whole"]


def test_hamp_pick_up_shows_its_pattern_and_fitts_duration() -> None:
    robot = a2ml.Robot.from_urdf(COMAN)
    start = np.radians([-10.0, -15.0, 45.0, -100.0, 0.0, 0.0, 0.0])
    pw, ow, swivel = robot.cpsa(start)
    turn = np.array([[math.cos(0.3), -math.sin(0.3), 0], [math.sin(0.3), math.cos(0.3), 0], [0, 0, 1]])
    target = pw + np.array([0.10, -0.08, 0.11])
    planned = a2ml.metrics.plan_handover(robot, start, target, turn @ ow, swivel + 0.35, seed=7)
    assert (planned["phase1"], planned["phase2"]) == ("ΦPO", "ΦPO-PO")
    travel = float(np.linalg.norm(target - pw))
    assert abs(planned["duration"] - a2ml.metrics.fitts_duration(travel)) < 1e-12
    assert planned["t"][-1] == planned["duration"]
    patterns = planned["metrics"]["whole"]["patterns"]
    assert patterns["phase1"]["hamp"] == planned["phase1"]
    assert patterns["phase2"]["hamp"] == planned["phase2"]
    assert planned["limit_violations"] == 0
    with pytest.raises(ValueError, match="handover"):
        a2ml.metrics.plan_handover(robot, start, target, ow, handover="wave")
