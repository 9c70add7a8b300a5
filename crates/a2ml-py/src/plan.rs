//! `a2ml.plan`, `a2ml.Plan` and `a2ml.SegmentReport`: a task planned into one joint
//! trajectory at the output rate, what each segment did, and the writers of docs/design.md §6.
//!
//! Arrays are float64: `t` (N,) s, `q` and `qd` (N, 7) rad and rad/s, the wrist reference
//! (M, 4) as t, x, y, z (s, m in {b}). Every enum value is spelled as the core spells it
//! (`as_str`, the serde name; docs/cli.md lists them); the small records are the NamedTuples of
//! `a2ml._types`, filled by field name from the core's serde representation. A plan keeps its
//! `Robot` and `Task` (whose source MCAP attaches) and pickles as its JSON, which the core
//! reads back, with the wall-clock timings that plan files leave out.

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::PathBuf;

use a2ml_core::language::SolverChoice;
use a2ml_core::math::{DOF, JointVector, Real};
use a2ml_core::output;
use a2ml_core::solve::{self, Plan, PlanOptions, SegmentReport, VariableError};
use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyString, PyTuple, PyType};
use rayon::prelude::*;
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::language::{self, PyTask};
use crate::{CoreError, Matrix, PyRobot, Vector, to_vector};

type Dict<'py> = Bound<'py, PyDict>;

/// A robot file and its chain's `base` and `tip`: the key of a robot loaded once per batch.
type RobotKey = (PathBuf, Option<String>, Option<String>);

/// Plans a task, or the task file at a path, on its robot (or `robot`), releasing the GIL.
#[pyfunction]
#[pyo3(signature = (
    task_or_path, solver=None, rate=None, seed=None, robot=None, acceleration_scale=None,
    time_limit=None
))]
// One argument per Python keyword: the signature is the Python API.
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan(
    py: Python<'_>,
    task_or_path: &Bound<'_, PyAny>,
    solver: Option<&str>,
    rate: Option<Real>,
    seed: Option<u64>,
    robot: Option<Bound<'_, PyRobot>>,
    acceleration_scale: Option<Real>,
    time_limit: Option<Real>,
) -> PyResult<PyPlan> {
    let task = match task_or_path.cast::<PyTask>() {
        Ok(task) => task.clone(),
        Err(_) => Bound::new(py, language::load(py, task_path(task_or_path)?)?)?,
    };
    let options = plan_options(solver, rate, acceleration_scale, time_limit)?;
    let planned_task = seeded(&task.get().task, seed);
    let robot = match robot {
        Some(robot) => robot.unbind(),
        None => Py::new(py, PyRobot::of_task(py, &planned_task)?)?,
    };
    let planned = py
        .detach(|| solve::plan(&robot.get().robot, &planned_task, &options))
        .map_err(CoreError::from)?;
    Ok(PyPlan { plan: planned, robot, task: task.unbind() })
}

/// Plans many tasks (Tasks or paths) on `jobs` threads (default: every core), releasing the
/// GIL: one entry per task, in input order, a Plan or the exception `plan` would have raised.
/// Robots are loaded once each (`robot`, else each task's robot with its base and tip).
#[pyfunction]
#[pyo3(signature = (
    tasks, robot=None, jobs=None, solver=None, rate=None, seed=None, acceleration_scale=None,
    time_limit=None
))]
// One argument per Python keyword: the signature is the Python API.
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan_many(
    py: Python<'_>,
    tasks: &Bound<'_, PyAny>,
    robot: Option<Bound<'_, PyRobot>>,
    jobs: Option<usize>,
    solver: Option<&str>,
    rate: Option<Real>,
    seed: Option<u64>,
    acceleration_scale: Option<Real>,
    time_limit: Option<Real>,
) -> PyResult<Vec<Py<PyAny>>> {
    if jobs == Some(0) {
        return Err(PyValueError::new_err("jobs must be at least 1"));
    }
    let options = plan_options(solver, rate, acceleration_scale, time_limit)?;
    let mut robots: HashMap<RobotKey, PyResult<Py<PyRobot>>> = HashMap::new();
    let mut entries: Vec<PyResult<(Bound<'_, PyTask>, Py<PyRobot>)>> = Vec::new();
    for item in tasks.try_iter()? {
        let item = item?;
        let task = match item.cast::<PyTask>() {
            Ok(task) => Ok(task.clone()),
            Err(_) => task_path(&item)
                .and_then(|path| language::load(py, path))
                .and_then(|task| Bound::new(py, task)),
        };
        let entry = task.and_then(|task| {
            let robot = match &robot {
                Some(robot) => robot.clone().unbind(),
                None => {
                    let t = &task.get().task;
                    let key = (t.robot.clone(), t.robot_base.clone(), t.robot_tip.clone());
                    let loaded =
                        robots.entry(key).or_insert_with(|| Py::new(py, PyRobot::of_task(py, t)?));
                    match loaded {
                        Ok(robot) => robot.clone_ref(py),
                        Err(e) => return Err(e.clone_ref(py)),
                    }
                }
            };
            Ok((task, robot))
        });
        entries.push(entry);
    }
    let work: Vec<(&a2ml_core::Robot, Cow<'_, a2ml_core::language::Task>)> = entries
        .iter()
        .filter_map(|entry| entry.as_ref().ok())
        .map(|(task, robot)| (&robot.get().robot, seeded(&task.get().task, seed)))
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.unwrap_or(0))
        .build()
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the planning threads: {e}")))?;
    let planned: Vec<Result<Plan, solve::SolveError>> = py.detach(|| {
        pool.install(|| {
            work.par_iter().map(|(robot, task)| solve::plan(robot, task, &options)).collect()
        })
    });
    let mut planned = planned.into_iter();
    entries
        .into_iter()
        .map(|entry| {
            let outcome = entry.and_then(|(task, robot)| {
                // One result per task that reached the planner, in order.
                let plan = planned.next().ok_or_else(|| {
                    PyRuntimeError::new_err("plan_many lost a result (a bug in a2ml)")
                })?;
                let plan = plan.map_err(CoreError::from)?;
                Ok(Py::new(py, PyPlan { plan, robot, task: task.unbind() })?.into_any())
            });
            Ok(outcome.unwrap_or_else(|e| e.into_value(py).into_any()))
        })
        .collect()
}

/// The task with `seed` as its seed, when given.
fn seeded(
    task: &a2ml_core::language::Task,
    seed: Option<u64>,
) -> Cow<'_, a2ml_core::language::Task> {
    match seed {
        Some(seed) => {
            let mut seeded = task.clone();
            seeded.settings.seed = seed;
            Cow::Owned(seeded)
        }
        None => Cow::Borrowed(task),
    }
}

/// The options `plan` and `plan_many` take.
fn plan_options(
    solver: Option<&str>,
    rate: Option<Real>,
    acceleration_scale: Option<Real>,
    time_limit: Option<Real>,
) -> PyResult<PlanOptions> {
    Ok(PlanOptions {
        solver: solver.map(solver_choice).transpose()?,
        rate,
        acceleration_scale,
        time_limit,
        ..PlanOptions::default()
    })
}

/// `task_or_path` as a path, or the TypeError naming what it was.
pub(crate) fn task_path(value: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    value.extract::<PathBuf>().map_err(|_| {
        let kind = value.get_type().name().map_or_else(|_| "?".to_owned(), |n| n.to_string());
        PyTypeError::new_err(format!("task_or_path must be an a2ml.Task or a path, not {kind}"))
    })
}

pub(crate) fn solver_choice(name: &str) -> PyResult<SolverChoice> {
    name.parse()
        .map_err(|e: a2ml_core::spelling::UnknownSpelling| PyValueError::new_err(e.to_string()))
}

/// A planned task: the joint trajectory at the output rate and one report per segment;
/// immutable. Keeps the `Robot` and `Task` it was planned from; pickles as its data.
#[pyclass(frozen, module = "a2ml", name = "Plan")]
pub(crate) struct PyPlan {
    pub(crate) plan: Plan,
    pub(crate) robot: Py<PyRobot>,
    task: Py<PyTask>,
}

#[pymethods]
impl PyPlan {
    /// Sample times (s), shape (N,): every 1 / rate from 0, and the end.
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Vector<'py> {
        to_vector(py, self.plan.trajectory.times())
    }

    /// Joint positions (rad), shape (N, 7).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Matrix<'py> {
        joint_rows(py, self.plan.trajectory.positions())
    }

    /// Joint velocities (rad/s), shape (N, 7).
    #[getter]
    fn qd<'py>(&self, py: Python<'py>) -> Matrix<'py> {
        joint_rows(py, self.plan.trajectory.velocities())
    }

    /// The human-likeness measures (`a2ml.metrics.analyze`): per-frame arrays and per-segment
    /// summaries.
    fn metrics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::metrics::plan_metrics(py, &self.plan, &self.robot.get().robot)
    }

    /// Joint names, in the order of the columns of q.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.plan.joint_names.clone()
    }

    /// Output rate (Hz).
    #[getter]
    fn rate(&self) -> Real {
        self.plan.rate
    }

    /// One report per segment, in time order.
    #[getter]
    fn segments(&self) -> Vec<PySegmentReport> {
        self.plan.segments.iter().map(|r| PySegmentReport { report: r.clone() }).collect()
    }

    /// Goals missed, fallbacks and repairs: `PlanWarning(kind, action, segment, message)`
    /// each, `str()` its message.
    #[getter]
    fn warnings<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
        self.plan.warnings.iter().map(|w| record(py, "PlanWarning", w, None)).collect()
    }

    /// Whether every segment reached its goals within tolerance.
    #[getter]
    fn reached(&self) -> bool {
        self.plan.reached()
    }

    /// The reference wrist path: rows (t, x, y, z) in s and m in {b}, shape (M, 4).
    #[getter]
    fn wrist_reference<'py>(&self, py: Python<'py>) -> Matrix<'py> {
        let rows = &self.plan.wrist_reference;
        Array2::from_shape_fn((rows.len(), 4), |(i, j)| match j {
            0 => rows[i].0,
            _ => rows[i].1[j - 1],
        })
        .into_pyarray(py)
    }

    /// The running segment's references per sample: `segment` (N,), `pw` (N, 3), `ow` and
    /// `shoulder_frame` (N, 4, quaternions x y z w), `swivel` and `elbow_angle` (N,), in m,
    /// rad and {b}; NaN where a variable is undefined.
    #[getter]
    fn references<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::plot::references(py, &self.plan)
    }

    /// Each moving arm capsule's signed distance to each obstacle per sample (m), keyed by
    /// (capsule, obstacle); NaN while the action touches the obstacle on purpose.
    #[getter]
    fn distances<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::plot::distances(py, &self.plan)
    }

    /// The distance the solvers kept from obstacles (m).
    #[getter]
    fn safety_distance(&self) -> Real {
        self.plan.safety_distance
    }

    /// The task that was planned.
    #[getter]
    fn task(&self, py: Python<'_>) -> Py<PyTask> {
        self.task.clone_ref(py)
    }

    /// The robot it was planned on.
    #[getter]
    fn robot(&self, py: Python<'_>) -> Py<PyRobot> {
        self.robot.clone_ref(py)
    }

    /// Writes the MCAP recording for Foxglove, releasing the GIL.
    fn write_mcap(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let (robot, task) = (&self.robot.get().robot, self.task.get());
        py.detach(|| output::write_mcap(&path, robot, &task.task, &task.source, &self.plan))
            .map_err(CoreError::from)?;
        Ok(())
    }

    /// Writes the joint trajectory as CSV, releasing the GIL.
    fn to_csv(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let robot = &self.robot.get().robot;
        py.detach(|| output::write_csv(&path, robot, &self.plan)).map_err(CoreError::from)?;
        Ok(())
    }

    /// Writes the plan as JSON, releasing the GIL.
    fn to_json(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let (robot, task) = (&self.robot.get().robot, &self.task.get().task);
        py.detach(|| output::write_json(&path, robot, task, &self.plan))
            .map_err(CoreError::from)?;
        Ok(())
    }

    /// Writes one row per sample as Parquet, releasing the GIL: `task` (`task_id`, default
    /// the task's name), `action`, `action_index`, `segment`, `t`, `q1`..`q7`, `qd1`..`qd7`,
    /// `pw_x`..`pw_z`, `ow_w`..`ow_z`, `swivel`, `clearance` (s, m, rad; {b}).
    #[pyo3(signature = (path, task_id=None))]
    fn to_parquet(&self, py: Python<'_>, path: PathBuf, task_id: Option<&str>) -> PyResult<()> {
        let (robot, task) = (&self.robot.get().robot, &self.task.get().task);
        let id = task_id.unwrap_or(&self.plan.task);
        py.detach(|| output::write_parquet(&path, robot, task, &self.plan, id))
            .map_err(CoreError::from)?;
        Ok(())
    }

    /// The table of `to_parquet` as a `pyarrow.Table` (pyarrow must be installed), which
    /// `to_pandas()` and `polars.from_arrow` take as it is.
    #[pyo3(signature = (task_id=None))]
    fn to_arrow<'py>(&self, py: Python<'py>, task_id: Option<&str>) -> PyResult<Bound<'py, PyAny>> {
        let parquet = py.import("pyarrow.parquet").map_err(|e| {
            pyo3::exceptions::PyImportError::new_err(format!(
                "Plan.to_arrow needs pyarrow (pip install pyarrow): {e}"
            ))
        })?;
        let (robot, task) = (&self.robot.get().robot, &self.task.get().task);
        let id = task_id.unwrap_or(&self.plan.task);
        let bytes = py
            .detach(|| output::parquet_bytes(robot, task, &self.plan, id))
            .map_err(CoreError::from)?;
        let buffer =
            py.import("pyarrow")?.getattr("BufferReader")?.call1((PyBytes::new(py, &bytes),))?;
        parquet.getattr("read_table")?.call1((buffer,))
    }

    /// The plan drawn as an SVG document: `kind` is one of `joints`, `velocities`,
    /// `featured`, `distances`, `wrist`, `all`.
    #[pyo3(signature = (kind="all"))]
    fn to_svg(&self, py: Python<'_>, kind: &str) -> PyResult<String> {
        let (robot, task) = (&self.robot.get().robot, &self.task.get().task);
        crate::plot::svg(py, robot, task, &self.plan, crate::plot::kind(kind)?)
    }

    /// Writes the plan drawn as `kind` (as [`Self::to_svg`]) to an SVG file, or a PNG image
    /// for a `.png` path, `width` pixels wide.
    #[pyo3(signature = (path, kind="all", width=None))]
    fn plot(&self, py: Python<'_>, path: PathBuf, kind: &str, width: Option<u32>) -> PyResult<()> {
        let (robot, task) = (&self.robot.get().robot, &self.task.get().task);
        crate::plot::write(py, &path, robot, task, &self.plan, crate::plot::kind(kind)?, width)
    }

    /// The self-contained HTML report: summary, segments, motion playback, plots, task.
    fn to_html(&self, py: Python<'_>) -> PyResult<String> {
        let (robot, task) = (&self.robot.get().robot, self.task.get());
        crate::plot::html(py, robot, &task.task, &task.source, &self.plan)
    }

    /// Writes the HTML report (as [`Self::to_html`]) to a file.
    fn write_report(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let (robot, task) = (&self.robot.get().robot, self.task.get());
        crate::plot::write_report(py, &path, robot, &task.task, &task.source, &self.plan)
    }

    /// The notebook view: the segment table and the joint plot.
    fn _repr_html_(&self, py: Python<'_>) -> PyResult<String> {
        let (robot, task) = (&self.robot.get().robot, &self.task.get().task);
        crate::plot::notebook(py, robot, task, &self.plan)
    }

    /// Pickles as `Plan._from_json(robot, task, json, timings)`: the plan as the core
    /// serialises it, and each segment's wall-clock timings, which plan files leave out.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let this = slf.get();
        let json = to_json(&this.plan)?;
        let timings: Vec<Timings> = this.plan.segments.iter().map(timings).collect();
        let rebuild = slf.get_type().getattr("_from_json")?;
        let args =
            (this.robot.clone_ref(py), this.task.clone_ref(py), json, timings).into_pyobject(py)?;
        PyTuple::new(py, [rebuild, args.into_any()])
    }

    /// The inverse of `__reduce__`.
    #[classmethod]
    fn _from_json(
        _cls: &Bound<'_, PyType>,
        robot: Py<PyRobot>,
        task: Py<PyTask>,
        json: &str,
        timings: Vec<Timings>,
    ) -> PyResult<Self> {
        let mut plan: Plan = from_json(json, "plan")?;
        if timings.len() != plan.segments.len() {
            return Err(PyValueError::new_err(format!(
                "invalid plan state: {} timings for {} segments",
                timings.len(),
                plan.segments.len()
            )));
        }
        for (report, t) in plan.segments.iter_mut().zip(timings) {
            with_timings(report, t);
        }
        Ok(Self { plan, robot, task })
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "Plan(task={}, samples={}, duration={}, segments={}, reached={})",
            PyString::new(py, &self.plan.task).repr()?,
            self.plan.trajectory.len(),
            self.plan.trajectory.duration(),
            self.plan.segments.len(),
            if self.plan.reached() { "True" } else { "False" }
        ))
    }
}

/// Joint vectors as the rows of an (N, 7) array.
pub(crate) fn joint_rows<'py>(py: Python<'py>, rows: &[JointVector]) -> Matrix<'py> {
    Array2::from_shape_fn((rows.len(), DOF), |(i, j)| rows[i][j]).into_pyarray(py)
}

/// `value` as the core serialises it.
fn to_json<T: Serialize>(value: &T) -> PyResult<String> {
    serde_json::to_string(value)
        .map_err(|e| PyRuntimeError::new_err(format!("cannot serialise (a bug in a2ml): {e}")))
}

/// A `what` read back from the core's serialisation, or a ValueError saying why not.
fn from_json<T: DeserializeOwned>(json: &str, what: &str) -> PyResult<T> {
    serde_json::from_str(json).map_err(|e| PyValueError::new_err(format!("invalid {what}: {e}")))
}

/// `value`'s serde representation as Python objects (dicts, lists, str, float, int, None).
fn to_python<'py, T: Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.getattr("loads")?.call1((to_json(value)?,))
}

/// The NamedTuple `name` of `a2ml._types` with `value`'s serialised fields, by name, and
/// `extra` ones (the wall-clock timings the serialisation leaves out).
fn record<'py, T: Serialize>(
    py: Python<'py>,
    name: &str,
    value: &T,
    extra: Option<Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let fields = to_python(py, value)?.cast_into::<PyDict>()?;
    if let Some(extra) = extra {
        fields.update(extra.as_mapping())?;
    }
    py.import("a2ml._types")?.getattr(name)?.call((), Some(&fields))
}

/// A segment's wall-clock timings, which plan files leave out: the QP's mean, worst, median
/// fast and median Clarabel step (s), and the RRT's time when it ran.
type Timings = (Real, Real, Real, Real, Option<Real>);

fn timings(report: &SegmentReport) -> Timings {
    let q = &report.qp;
    let rrt = report.rrt.as_ref().map(|r| r.time);
    (q.mean_step_time, q.worst_step_time, q.median_fast_time, q.median_clarabel_time, rrt)
}

fn with_timings(report: &mut SegmentReport, (mean, worst, fast, clarabel, rrt): Timings) {
    report.qp.mean_step_time = mean;
    report.qp.worst_step_time = worst;
    report.qp.median_fast_time = fast;
    report.qp.median_clarabel_time = clarabel;
    if let (Some(stats), Some(time)) = (report.rrt.as_mut(), rrt) {
        stats.time = time;
    }
}

/// What one movement segment did; immutable, equal when every field is.
#[pyclass(frozen, module = "a2ml", name = "SegmentReport")]
pub(crate) struct PySegmentReport {
    report: SegmentReport,
}

#[pymethods]
impl PySegmentReport {
    /// The action's name.
    #[getter]
    fn action(&self) -> &str {
        &self.report.action
    }

    /// The action's index in `Task.actions`.
    #[getter]
    fn action_index(&self) -> usize {
        self.report.action_index
    }

    /// The segment's index within its action (0-based).
    #[getter]
    fn segment(&self) -> usize {
        self.report.segment
    }

    /// The paper's type, "i" to "vii", or None for an action written as explicit segments.
    #[getter]
    fn action_type(&self) -> Option<&'static str> {
        self.report.action_type.map(|t| t.as_str())
    }

    /// "cpsa" or "hat".
    #[getter]
    fn space(&self) -> &'static str {
        self.report.space.as_str()
    }

    /// The paper's pattern: "path" (1), "goal" (2) or "mixed" (3).
    #[getter]
    fn pattern(&self) -> &'static str {
        self.report.pattern.as_str()
    }

    /// The solver that produced the motion.
    #[getter]
    fn solver(&self) -> &'static str {
        self.report.solver.as_str()
    }

    /// The focus of interest: the variables of the featured primitive.
    #[getter]
    fn focus(&self) -> Vec<&'static str> {
        language::variable_names(&self.report.focus)
    }

    /// Start in the plan's time (s).
    #[getter]
    fn start(&self) -> Real {
        self.report.start
    }

    /// End in the plan's time (s), settling included.
    #[getter]
    fn end(&self) -> Real {
        self.report.end
    }

    /// The segment's own duration before joining (s).
    #[getter]
    fn duration(&self) -> Real {
        self.report.duration
    }

    /// Time run past the reference's end to settle on the goal (s).
    #[getter]
    fn settle(&self) -> Real {
        self.report.settle
    }

    /// Final error of every variable of the space: `{variable: VariableError}`.
    #[getter]
    fn errors<'py>(&self, py: Python<'py>) -> PyResult<Dict<'py>> {
        variable_errors(py, &self.report.errors)
    }

    /// Largest distance of each path variable from its path (its locus, whatever the timing).
    #[getter]
    fn path_errors<'py>(&self, py: Python<'py>) -> PyResult<Dict<'py>> {
        variable_errors(py, &self.report.path_errors)
    }

    /// Whether the path is a hard constraint (an action of type IV or VI).
    #[getter]
    fn hard_path(&self) -> bool {
        self.report.hard_path
    }

    /// Whether the path was kept within tolerance throughout (always True for a soft path).
    #[getter]
    fn path_kept(&self) -> bool {
        self.report.path_kept
    }

    /// Why `auto` went on from the QP to the solver named: "qp_stalled", "qp_missed_goal",
    /// "qp_left_path", or None.
    #[getter]
    fn fallback(&self) -> Option<&'static str> {
        self.report.fallback.map(|f| f.as_str())
    }

    /// The largest |q'| / velocity limit of any joint over the segment's time in the output.
    #[getter]
    fn peak_velocity_ratio(&self) -> Real {
        self.report.peak_velocity_ratio
    }

    /// The largest |q''| / acceleration limit of any joint over the segment's time in the output.
    #[getter]
    fn peak_acceleration_ratio(&self) -> Real {
        self.report.peak_acceleration_ratio
    }

    /// Whether the output holds every position, velocity and acceleration limit over the segment.
    #[getter]
    fn limits_kept(&self) -> bool {
        self.report.limits_kept
    }

    /// The factor the segment was slowed down by to keep the limits (1: as solved).
    #[getter]
    fn slowed_down(&self) -> Real {
        self.report.slowed_down
    }

    /// The normalised jerk of the joints over the segment (dimensionless).
    #[getter]
    fn joint_jerk(&self) -> Real {
        self.report.joint_jerk
    }

    /// The normalised jerk of the wrist path over the segment (dimensionless).
    #[getter]
    fn wrist_jerk(&self) -> Real {
        self.report.wrist_jerk
    }

    /// The number of peaks of the featured variable's speed (1: one bell).
    #[getter]
    fn speed_peaks(&self) -> usize {
        self.report.speed_peaks
    }

    /// The smallest clearance over the segment, or None.
    #[getter]
    fn clearance<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.report.clearance.as_ref().map(|c| record(py, "Clearance", c, None)).transpose()
    }

    /// Smallest distance of any joint to its limits over the segment (rad).
    #[getter]
    fn limit_margin(&self) -> Real {
        self.report.limit_margin
    }

    /// Whether the solver stopped making progress short of the goal.
    #[getter]
    fn stalled(&self) -> bool {
        self.report.stalled
    }

    /// Whether every variable is within tolerance at the end.
    #[getter]
    fn reached(&self) -> bool {
        self.report.reached
    }

    /// QP counters and timings.
    #[getter]
    fn qp<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let s = &self.report.qp;
        let times = PyDict::new(py);
        times.set_item("mean_step_time", s.mean_step_time)?;
        times.set_item("worst_step_time", s.worst_step_time)?;
        times.set_item("median_fast_time", s.median_fast_time)?;
        times.set_item("median_clarabel_time", s.median_clarabel_time)?;
        record(py, "QpStats", s, Some(times))
    }

    /// RRT counters when the RRT solved the segment.
    #[getter]
    fn rrt<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.report
            .rrt
            .as_ref()
            .map(|s| {
                let time = PyDict::new(py);
                time.set_item("time", s.time)?;
                record(py, "RrtStats", s, Some(time))
            })
            .transpose()
    }

    /// Every field as one dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Dict<'py>> {
        let d = PyDict::new(py);
        d.set_item("action", self.action())?;
        d.set_item("action_index", self.action_index())?;
        d.set_item("segment", self.segment())?;
        d.set_item("action_type", self.action_type())?;
        d.set_item("space", self.space())?;
        d.set_item("pattern", self.pattern())?;
        d.set_item("solver", self.solver())?;
        d.set_item("focus", self.focus())?;
        d.set_item("start", self.start())?;
        d.set_item("end", self.end())?;
        d.set_item("duration", self.duration())?;
        d.set_item("settle", self.settle())?;
        d.set_item("errors", self.errors(py)?)?;
        d.set_item("path_errors", self.path_errors(py)?)?;
        d.set_item("hard_path", self.hard_path())?;
        d.set_item("path_kept", self.path_kept())?;
        d.set_item("clearance", self.clearance(py)?)?;
        d.set_item("limit_margin", self.limit_margin())?;
        d.set_item("stalled", self.stalled())?;
        d.set_item("reached", self.reached())?;
        d.set_item("qp", self.qp(py)?)?;
        d.set_item("rrt", self.rrt(py)?)?;
        d.set_item("fallback", self.fallback())?;
        d.set_item("peak_velocity_ratio", self.peak_velocity_ratio())?;
        d.set_item("peak_acceleration_ratio", self.peak_acceleration_ratio())?;
        d.set_item("limits_kept", self.limits_kept())?;
        d.set_item("slowed_down", self.slowed_down())?;
        d.set_item("joint_jerk", self.joint_jerk())?;
        d.set_item("wrist_jerk", self.wrist_jerk())?;
        d.set_item("speed_peaks", self.speed_peaks())?;
        Ok(d)
    }

    /// Pickles as `SegmentReport._from_json(json, timings)`, as a plan does.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let report = &slf.get().report;
        let rebuild = slf.get_type().getattr("_from_json")?;
        let args = (to_json(report)?, timings(report)).into_pyobject(py)?;
        PyTuple::new(py, [rebuild, args.into_any()])
    }

    /// The inverse of `__reduce__`.
    #[classmethod]
    fn _from_json(_cls: &Bound<'_, PyType>, json: &str, timings: Timings) -> PyResult<Self> {
        let mut report: SegmentReport = from_json(json, "segment report")?;
        with_timings(&mut report, timings);
        Ok(Self { report })
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.report == other.report
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "SegmentReport(action={}, segment={}, space={:?}, solver={:?}, reached={})",
            PyString::new(py, &self.report.action).repr()?,
            self.report.segment,
            self.space(),
            self.solver(),
            if self.report.reached { "True" } else { "False" }
        ))
    }
}

/// `{variable: VariableError(variable, error, within)}` in the space's order.
fn variable_errors<'py>(py: Python<'py>, errors: &[VariableError]) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    for e in errors {
        d.set_item(e.variable.as_str(), record(py, "VariableError", e, None)?)?;
    }
    Ok(d)
}
