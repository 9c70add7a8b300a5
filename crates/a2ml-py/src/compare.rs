//! `a2ml.compare`: one task planned by several solvers, as a list of flat records (dicts)
//! that `pandas.DataFrame` takes as they are: one per solver and segment, or one carrying
//! the error of a solver that produced no plan. Goal and path errors are flattened into
//! `error_<variable>` and `path_error_<variable>` keys (pw, ow, swivel, shoulder_frame, elbow).

use a2ml_core::language::SolverChoice;
use a2ml_core::solve::PlanOptions;
use a2ml_core::solve::compare::{ComparisonRecord, compare as compare_solvers, records};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::PyRobot;
use crate::language::{self, PyTask};
use crate::plan::{solver_choice, task_path};

/// The default solvers: A2ML's own policy and the three baselines.
const DEFAULT_SOLVERS: [SolverChoice; 4] =
    [SolverChoice::Auto, SolverChoice::Gpm, SolverChoice::Clik, SolverChoice::Pmp];

/// Plans a task (or the task file at a path) once per solver and returns the comparison
/// records, releasing the GIL.
#[pyfunction]
#[pyo3(signature = (task_or_path, solvers=None, robot=None))]
pub(crate) fn compare<'py>(
    py: Python<'py>,
    task_or_path: &Bound<'py, PyAny>,
    solvers: Option<Vec<String>>,
    robot: Option<Bound<'py, PyRobot>>,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let task = match task_or_path.cast::<PyTask>() {
        Ok(task) => task.clone(),
        Err(_) => Bound::new(py, language::load(py, task_path(task_or_path)?)?)?,
    };
    let solvers: Vec<SolverChoice> = match solvers {
        Some(names) => names.iter().map(|n| solver_choice(n)).collect::<PyResult<_>>()?,
        None => DEFAULT_SOLVERS.to_vec(),
    };
    let task = &task.get().task;
    let robot = match robot {
        Some(robot) => robot.unbind(),
        None => Py::new(py, PyRobot::of_task(py, task)?)?,
    };
    let robot = &robot.get().robot;
    let rows: Vec<ComparisonRecord> = py.detach(|| {
        let attempts = compare_solvers(robot, task, &solvers, &PlanOptions::default());
        attempts.iter().flat_map(|a| records(robot, a)).collect()
    });
    rows.iter().map(|r| record(py, r)).collect()
}

fn record<'py>(py: Python<'py>, r: &ComparisonRecord) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("solver", &r.solver)?;
    d.set_item("solved_by", &r.solved_by)?;
    d.set_item("action", &r.action)?;
    d.set_item("segment", r.segment)?;
    d.set_item("reached", r.reached)?;
    d.set_item("path_kept", r.path_kept)?;
    for (variable, error) in &r.errors {
        d.set_item(format!("error_{variable}"), error)?;
    }
    for (variable, error) in &r.path_errors {
        d.set_item(format!("path_error_{variable}"), error)?;
    }
    d.set_item("limit_margin", r.limit_margin)?;
    d.set_item("limit_joint", &r.limit_joint)?;
    d.set_item("clearance", r.clearance)?;
    d.set_item("clearance_link", &r.clearance_link)?;
    d.set_item("peak_speed_ratio", r.peak_speed_ratio)?;
    d.set_item("duration", r.duration)?;
    d.set_item("planning_time", r.planning_time)?;
    d.set_item("error", &r.error)?;
    Ok(d)
}
