"""a2ml.compare: flat records per solver and segment, a failing solver as one
record with its error."""

from __future__ import annotations

from pathlib import Path

import a2ml

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "baseline_pmp.a2ml"


def test_compare_returns_flat_records() -> None:
    records = a2ml.compare(EXAMPLE, solvers=["qp", "pmp", "hamp"])
    assert [r["solver"] for r in records] == ["qp", "qp", "pmp", "pmp", "hamp"]
    pmp = records[2]
    assert pmp["solved_by"] == "pmp" and pmp["action"] == "out_diagonal"
    assert isinstance(pmp["error_pw"], float) and pmp["error_pw"] < 1e-3
    assert pmp["path_error_pw"] > records[0]["path_error_pw"]
    assert isinstance(pmp["limit_joint"], str) and pmp["planning_time"] > 0.0
    assert records[4]["error"] is not None and "not available yet" in records[4]["error"]
