//! `Plan.plot` (SVG or PNG), `Plan.to_svg`, `Plan.to_html`, `Plan.write_report` and `Plan._repr_html_`:
//! the core's pictures and report of a plan (`a2ml_core::output::plot` and `::report`),
//! drawn with the GIL released. Kinds are named as `a2ml plot --kind` names them.

use std::path::Path;

use a2ml_core::Robot;
use a2ml_core::language::Task;
use a2ml_core::math::Real;
use a2ml_core::output::plot::{self, PlotKind};
use a2ml_core::output::report::{self, ReportInput};
use a2ml_core::solve::Plan;
use numpy::IntoPyArray;
use numpy::ndarray::{Array1, Array2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{A2mlError, CoreError};

/// The kind named `name`, or the ValueError listing the kinds.
pub(crate) fn kind(name: &str) -> PyResult<PlotKind> {
    PlotKind::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = PlotKind::NAMES.iter().map(|(n, _)| *n).collect();
        PyValueError::new_err(format!("unknown plot kind '{name}' ({})", names.join(", ")))
    })
}

/// A drawing the backend refused: a2ml's base error.
fn refused(e: impl std::fmt::Display) -> PyErr {
    A2mlError::new_err(e.to_string())
}

/// The SVG document of `kind`.
pub(crate) fn svg(
    py: Python<'_>,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    kind: PlotKind,
) -> PyResult<String> {
    py.detach(|| plot::plot_svg(robot, task, plan, kind)).map(|p| p.svg).map_err(refused)
}

/// Writes the picture of `kind` to `path`: PNG for a `.png` name, else SVG; `width` pixels
/// wide (as drawn when `None`).
pub(crate) fn write(
    py: Python<'_>,
    path: &Path,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    kind: PlotKind,
    width: Option<u32>,
) -> PyResult<()> {
    if let Some(w) = width.filter(|w| *w == 0 || *w > plot::MAX_WIDTH) {
        return Err(PyValueError::new_err(format!(
            "width is 1 to {} pixels, not {w}",
            plot::MAX_WIDTH
        )));
    }
    py.detach(|| plot::write_plot(path, robot, task, plan, kind, width))
        .map_err(CoreError::from)?;
    Ok(())
}

/// The self-contained HTML report (without the decomposition, which `a2ml report` adds).
pub(crate) fn html(
    py: Python<'_>,
    robot: &Robot,
    task: &Task,
    source: &str,
    plan: &Plan,
) -> PyResult<String> {
    let input = ReportInput { robot, task, source, plan, decomposition: None };
    py.detach(|| report::report_html(&input)).map_err(refused)
}

/// Writes the HTML report to `path`.
pub(crate) fn write_report(
    py: Python<'_>,
    path: &Path,
    robot: &Robot,
    task: &Task,
    source: &str,
    plan: &Plan,
) -> PyResult<()> {
    let input = ReportInput { robot, task, source, plan, decomposition: None };
    py.detach(|| report::write_report(path, &input)).map_err(CoreError::from)?;
    Ok(())
}

/// The notebook view: caption, segment table and joint plot.
pub(crate) fn notebook(
    py: Python<'_>,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
) -> PyResult<String> {
    py.detach(|| report::notebook_html(robot, task, plan)).map_err(refused)
}

/// [`Plan::references`] as arrays, NaN where undefined.
pub(crate) fn references<'py>(py: Python<'py>, plan: &Plan) -> PyResult<Bound<'py, PyDict>> {
    let samples = &plan.references;
    let n = samples.len();
    let or_nan = |x: Option<Real>| x.unwrap_or(Real::NAN);
    let out = PyDict::new(py);
    let segment: Array1<i64> = samples.iter().map(|r| r.segment as i64).collect();
    out.set_item("segment", segment.into_pyarray(py))?;
    let pw = Array2::from_shape_fn((n, 3), |(i, j)| or_nan(samples[i].state.pw.map(|p| p[j])));
    out.set_item("pw", pw.into_pyarray(py))?;
    let quaternions =
        |pick: fn(&a2ml_core::solve::ReferenceState) -> Option<a2ml_core::math::UnitQuaternion>| {
            Array2::from_shape_fn((n, 4), |(i, j)| {
                or_nan(pick(&samples[i].state).map(|q| q.coords[j]))
            })
        };
    out.set_item("ow", quaternions(|s| s.ow).into_pyarray(py))?;
    out.set_item("shoulder_frame", quaternions(|s| s.shoulder_frame).into_pyarray(py))?;
    let angles = |pick: fn(&a2ml_core::solve::ReferenceState) -> Option<Real>| {
        samples.iter().map(|r| or_nan(pick(&r.state))).collect::<Array1<Real>>()
    };
    out.set_item("swivel", angles(|s| s.swivel).into_pyarray(py))?;
    out.set_item("elbow_angle", angles(|s| s.elbow_angle).into_pyarray(py))?;
    Ok(out)
}

/// [`Plan::distances`] keyed by (capsule, obstacle), NaN where not measured.
pub(crate) fn distances<'py>(py: Python<'py>, plan: &Plan) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    for d in &plan.distances {
        let values: Array1<Real> = d.distance.iter().map(|x| x.unwrap_or(Real::NAN)).collect();
        out.set_item((d.capsule.as_str(), d.obstacle.as_str()), values.into_pyarray(py))?;
    }
    Ok(out)
}
