//! `a2ml.decompose`: a task's actions, in execution order, as movement
//! segments with every value known, as plain Python data.
//!
//! Built by hand like the task data in [`crate::language`], whose spelling
//! it shares: variables as `Robot` names them, spaces `"cpsa"` / `"hat"`,
//! primitives in the shape of an explicit segment's. Joint vectors are
//! (7,) float64 arrays (rad).

use a2ml_core::decompose::{
    Classification, DecomposeOptions, Decomposition, OptReport, PlannedAction, PlannedSegment,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::language::{PyTask, primitive, space_name, variable_names};
use crate::{CoreError, PyRobot, to_vector};

type Dict<'py> = Bound<'py, PyDict>;

/// Decomposes a task into movement segments for `robot` (by default the
/// task's robot file), releasing the GIL.
#[pyfunction]
#[pyo3(signature = (task, robot=None))]
pub(crate) fn decompose<'py>(
    py: Python<'py>,
    task: &Bound<'py, PyTask>,
    robot: Option<&Bound<'py, PyRobot>>,
) -> PyResult<Dict<'py>> {
    let task = &task.get().task;
    let robot = robot.map(|r| &r.get().robot);
    let planned = py
        .detach(|| -> Result<Decomposition, a2ml_core::Error> {
            let loaded;
            let robot = match robot {
                Some(r) => r,
                None => {
                    loaded = task.load_robot(&a2ml_core::RobotOptions::default())?;
                    &loaded
                }
            };
            Ok(a2ml_core::decompose::decompose(robot, task, &DecomposeOptions::default())?)
        })
        .map_err(CoreError::from)?;
    decomposition(py, &planned)
}

/// `task`, `start` and `actions`.
fn decomposition<'py>(py: Python<'py>, d: &Decomposition) -> PyResult<Dict<'py>> {
    let dict = PyDict::new(py);
    dict.set_item("task", &d.task)?;
    dict.set_item("start", to_vector(py, d.start.as_slice()))?;
    let actions: Vec<Dict<'py>> =
        d.actions.iter().map(|a| action(py, a)).collect::<PyResult<_>>()?;
    dict.set_item("actions", actions)?;
    Ok(dict)
}

/// `index`, `name`, the classification (all None for an explicit action),
/// `segments` and `optimisations`.
fn action<'py>(py: Python<'py>, a: &PlannedAction) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    d.set_item("index", a.index)?;
    d.set_item("name", &a.name)?;
    let c: Option<&Classification> = a.classification.as_ref();
    d.set_item("type", c.map(|c| c.action_type.as_str()))?;
    d.set_item("type_number", c.map(|c| c.action_type.number()))?;
    d.set_item("description", c.map(|c| c.action_type.description()))?;
    d.set_item("goal_space", c.and_then(|c| c.goal_space).map(space_name))?;
    d.set_item("secondary_goal_space", c.and_then(|c| c.secondary_goal_space).map(space_name))?;
    d.set_item("path_space", c.and_then(|c| c.path_space).map(space_name))?;
    let segments: Vec<Dict<'py>> =
        a.segments.iter().map(|s| segment(py, s)).collect::<PyResult<_>>()?;
    d.set_item("segments", segments)?;
    let reports: Vec<Dict<'py>> =
        a.optimisations.iter().map(|r| report(py, r)).collect::<PyResult<_>>()?;
    d.set_item("optimisations", reports)?;
    Ok(d)
}

fn segment<'py>(py: Python<'py>, s: &PlannedSegment) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    d.set_item("space", space_name(s.space))?;
    d.set_item("pattern", s.pattern.as_str())?;
    d.set_item("duration", s.duration)?;
    d.set_item("duration_raised", s.duration_raised)?;
    d.set_item("solver", s.solver.as_str())?;
    d.set_item("relaxed", variable_names(&s.relaxed))?;
    d.set_item("start", to_vector(py, s.start.as_slice()))?;
    d.set_item("end", to_vector(py, s.end.as_slice()))?;
    let primitives: Vec<Dict<'py>> =
        s.primitives.iter().map(|p| primitive(py, p)).collect::<PyResult<_>>()?;
    d.set_item("primitives", primitives)?;
    Ok(d)
}

fn report<'py>(py: Python<'py>, r: &OptReport) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    d.set_item("solver", r.solver)?;
    d.set_item("residual", r.residual)?;
    d.set_item("sizes", &r.sizes)?;
    d.set_item("evaluations", r.evaluations)?;
    Ok(d)
}
