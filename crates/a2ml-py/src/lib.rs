//! Python bindings of a2ml-core, built by maturin into the `a2ml` wheel as
//! `a2ml._a2ml`. Thin by design: every method converts its inputs, calls
//! the core and converts the result; all kinematics lives in the core.
//! Arrays cross as float64 numpy arrays; frames and units as in docs/design.md §2.
//! The task language is in [`language`], the decomposition in
//! [`decompose`], planning and its outputs in [`plan`]; exceptions and their
//! mapping in [`errors`], numpy conversions in [`convert`], the robot in
//! [`robot`]; this file registers the module.

mod batch;
mod compare;
mod convert;
mod decompose;
mod errors;
mod language;
mod map;
mod metrics;
mod plan;
mod plot;
mod robot;
mod rrt;

use pyo3::prelude::*;

pub(crate) use convert::{
    Matrix, Vector, read_angle, read_array, read_joints, read_rotation, read_vector3, to_rotation,
    to_vector,
};
pub(crate) use errors::{
    A2mlError, ConvergenceError, CoreError, DecomposeError, JointLimitError, ParseError, PlanError,
    SingularityError, UnreachableError, UrdfError, os_error,
};
pub(crate) use robot::PyRobot;

/// The native module `a2ml._a2ml`; `a2ml/__init__.py` re-exports it.
#[pymodule]
fn _a2ml(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<PyRobot>()?;
    m.add_class::<language::PyTask>()?;
    m.add_function(wrap_pyfunction!(language::parse, m)?)?;
    m.add_function(wrap_pyfunction!(language::load, m)?)?;
    m.add_function(wrap_pyfunction!(decompose::decompose, m)?)?;
    m.add_class::<plan::PyPlan>()?;
    m.add_class::<plan::PySegmentReport>()?;
    m.add_function(wrap_pyfunction!(plan::plan, m)?)?;
    rrt::register(m)?;
    m.add_function(wrap_pyfunction!(plan::plan_many, m)?)?;
    m.add_function(wrap_pyfunction!(compare::compare, m)?)?;
    m.add_function(wrap_pyfunction!(map::swivel_map, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::_metrics_analyze, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::_metrics_similarity, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::_metrics_levenshtein, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::_metrics_connection_similarity, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::_metrics_mpcsi, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::_metrics_fitts_duration, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::_metrics_rula_table_a, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::_metrics_plan_handover, m)?)?;
    m.add("A2mlError", py.get_type::<A2mlError>())?;
    m.add("UrdfError", py.get_type::<UrdfError>())?;
    m.add("ParseError", py.get_type::<ParseError>())?;
    m.add("UnreachableError", py.get_type::<UnreachableError>())?;
    m.add("JointLimitError", py.get_type::<JointLimitError>())?;
    m.add("SingularityError", py.get_type::<SingularityError>())?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    m.add("DecomposeError", py.get_type::<DecomposeError>())?;
    m.add("PlanError", py.get_type::<PlanError>())?;
    Ok(())
}
