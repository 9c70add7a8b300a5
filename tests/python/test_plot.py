"""Pictures and the report from Python: Plan.to_svg and Plan.plot draw what
``a2ml plot`` draws (an SVG parsed here with the standard library), the report
is one page that fetches nothing, and a notebook shows the segment table and
the joint plot."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

import a2ml
from a2ml import Plan

TESTS_DIR = Path(__file__).resolve().parent
EXAMPLE = TESTS_DIR / ".." / ".." / "examples" / "construct_scene.a2ml"
SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module")
def plan() -> Plan:
    return a2ml.plan(EXAMPLE)


def test_every_kind_is_an_svg_naming_the_task(plan: Plan) -> None:
    for kind in ("joints", "velocities", "featured", "distances", "wrist", "all"):
        svg = plan.to_svg(kind)
        root = ET.fromstring(svg)
        assert root.tag == f"{SVG}svg"
        texts = " ".join(t.text or "" for t in root.iter(f"{SVG}text"))
        assert f"task {plan.task.name} · robot {plan.robot.name}" in texts
    all_texts = " ".join(t.text or "" for t in ET.fromstring(plan.to_svg()).iter(f"{SVG}text"))
    for name in plan.joint_names:
        assert name in all_texts


def test_plot_writes_what_to_svg_returns(plan: Plan, tmp_path: Path) -> None:
    path = tmp_path / "joints.svg"
    plan.plot(path, kind="joints")
    assert path.read_text(encoding="utf-8") == plan.to_svg("joints")


def png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert data[12:16] == b"IHDR"
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


def test_plot_to_a_png_path_writes_a_png_image(plan: Plan, tmp_path: Path) -> None:
    root = ET.fromstring(plan.to_svg("joints"))
    own = (int(root.attrib["width"]), int(root.attrib["height"]))
    path = tmp_path / "joints.png"
    plan.plot(path, kind="joints")
    assert png_size(path) == own
    plan.plot(path, kind="joints", width=400)
    width, height = png_size(path)
    assert width == 400 and abs(height - own[1] * 400 / own[0]) <= 1
    for bad in (0, 100_000):
        with pytest.raises(ValueError, match="width"):
            plan.plot(tmp_path / "bad.png", width=bad)
    assert not (tmp_path / "bad.png").exists()


def test_a_pickled_plan_keeps_its_swivel_maps_for_the_report() -> None:
    import pickle

    mapped = a2ml.plan(TESTS_DIR / ".." / ".." / "examples" / "swivel_map_spheres.a2ml")
    html = mapped.to_html()
    assert '<section id="swivel-maps">' in html
    again = pickle.loads(pickle.dumps(mapped))
    assert again.to_html() == html


def test_an_unknown_kind_is_a_value_error(plan: Plan, tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="wrist"):
        plan.to_svg("pie")  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        plan.plot(tmp_path / "x.svg", kind="pie")  # type: ignore[arg-type]
    assert not (tmp_path / "x.svg").exists()


def test_a_picture_into_a_missing_folder_is_an_os_error(plan: Plan, tmp_path: Path) -> None:
    with pytest.raises(OSError):
        plan.plot(tmp_path / "no" / "such" / "x.svg")


def test_the_report_is_one_page_that_fetches_nothing(plan: Plan, tmp_path: Path) -> None:
    html = plan.to_html()
    assert html.startswith("<!doctype html>")
    rest = html.replace("http://www.w3.org/2000/svg", "")
    assert "http" not in rest
    for fetching in ("src=", "<link", "@import"):
        assert fetching not in rest
    for segment in plan.segments:
        assert f"<td>{segment.action}</td>" in html
    path = tmp_path / "report.html"
    plan.write_report(path)
    assert path.read_text(encoding="utf-8") == html


def test_a_notebook_shows_the_table_and_the_joint_plot(plan: Plan) -> None:
    view = plan._repr_html_()
    assert '<table class="segments">' in view
    assert view.count("<tr>") == len(plan.segments) + 1
    assert "<svg" in view and "position" in view


def test_the_references_and_distances_are_per_sample(plan: Plan) -> None:
    import math
    import pickle

    import numpy as np

    n = len(plan.t)
    refs = plan.references
    assert refs["segment"].shape == (n,)
    assert refs["pw"].shape == (n, 3) and refs["ow"].shape == (n, 4)
    assert refs["swivel"].shape == (n,) and refs["elbow_angle"].shape == (n,)
    assert set(refs["segment"].tolist()) == set(range(len(plan.segments)))
    # Ow's reference is always a unit quaternion (every segment's space has Ow).
    assert np.allclose(np.linalg.norm(refs["ow"], axis=1), 1.0)
    distances = plan.distances
    assert distances, "construct_scene has obstacles"
    for (capsule, obstacle), values in distances.items():
        assert isinstance(capsule, str) and isinstance(obstacle, str)
        assert values.shape == (n,)
        finite = values[~np.isnan(values)]
        assert finite.size > 0 and math.isfinite(float(finite.min()))
    copy = pickle.loads(pickle.dumps(plan))
    assert np.array_equal(copy.references["pw"], refs["pw"], equal_nan=True)
    assert list(copy.distances) == list(distances)
