//! `Plan.plot`, `Plan.to_svg`, `Plan.to_html`, `Plan.write_report` and `Plan._repr_html_`:
//! the core's pictures and report of a plan (`a2ml_core::output::plot` and `::report`),
//! drawn with the GIL released. Kinds are named as `a2ml plot --kind` names them.

use std::path::Path;

use a2ml_core::Robot;
use a2ml_core::language::Task;
use a2ml_core::output::plot::{self, PlotKind};
use a2ml_core::output::report::{self, ReportInput};
use a2ml_core::solve::Plan;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

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

/// Writes the SVG document of `kind` to `path`.
pub(crate) fn write(
    py: Python<'_>,
    path: &Path,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    kind: PlotKind,
) -> PyResult<()> {
    py.detach(|| plot::write_plot(path, robot, task, plan, kind)).map_err(CoreError::from)?;
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
