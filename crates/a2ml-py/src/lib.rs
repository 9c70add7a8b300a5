//! Python bindings of a2ml-core, built by maturin into the `a2ml` wheel as
//! `a2ml._a2ml`. Thin by design: every method converts its inputs, calls
//! the core and converts the result; all kinematics lives in the core.
//! Arrays cross as float64 numpy arrays; frames and units as in docs/design.md §2.
//! The task language is in [`language`], the decomposition in
//! [`decompose`], planning and its outputs in [`plan`]; exceptions and their
//! mapping here.

mod compare;
mod decompose;
mod language;
mod map;
mod metrics;
mod plan;
mod plot;

use std::path::{Path, PathBuf};

use a2ml_core::kinematics::{self, CpsaState, HatState, KinematicsError};
use a2ml_core::language::{Diagnostics, LanguageError};
use a2ml_core::math::{DOF, JointVector, Matrix3, Real, Rotation3, Vector3};
use a2ml_core::output::OutputError;
use a2ml_core::robot::{RobotError, RobotOptions};
use a2ml_core::solve::SolveError;
use numpy::ndarray::Array2;
use numpy::{
    AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayLikeDyn, PyUntypedArrayMethods,
};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyOSError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple, PyType};

create_exception!(a2ml, A2mlError, PyException, "Base class of every error raised by a2ml.");
create_exception!(
    a2ml,
    UrdfError,
    A2mlError,
    "The URDF is missing, unreadable or not a 7-DoF arm."
);
create_exception!(
    a2ml,
    UnreachableError,
    A2mlError,
    "The wrist target is outside the reachable annulus."
);
create_exception!(
    a2ml,
    ParseError,
    A2mlError,
    "The text is not a valid A2ML task; `line`, `column`, `message` locate the first problem, `errors` lists all."
);
create_exception!(a2ml, JointLimitError, A2mlError, "Every IK solution leaves the joint limits.");
create_exception!(a2ml, SingularityError, A2mlError, "The configuration or target is singular.");
create_exception!(
    a2ml,
    ConvergenceError,
    A2mlError,
    "Numerical IK failed, or the arm has no closed form."
);
create_exception!(
    a2ml,
    DecomposeError,
    A2mlError,
    "The task cannot be decomposed into actions and movement segments."
);
create_exception!(
    a2ml,
    PlanError,
    A2mlError,
    "A decomposed task cannot be solved: a solver is unavailable, or a segment's references or QP fail."
);

/// A core error on its way to Python (polars' newtype pattern): the one
/// place that decides which exception class each error kind becomes.
struct CoreError(a2ml_core::Error);

impl From<RobotError> for CoreError {
    fn from(e: RobotError) -> Self {
        Self(e.into())
    }
}

impl From<KinematicsError> for CoreError {
    fn from(e: KinematicsError) -> Self {
        Self(e.into())
    }
}

impl From<LanguageError> for CoreError {
    fn from(e: LanguageError) -> Self {
        Self(e.into())
    }
}

impl From<SolveError> for CoreError {
    fn from(e: SolveError) -> Self {
        Self(e.into())
    }
}

impl From<OutputError> for CoreError {
    fn from(e: OutputError) -> Self {
        Self(e.into())
    }
}

impl From<a2ml_core::Error> for CoreError {
    fn from(e: a2ml_core::Error) -> Self {
        Self(e)
    }
}

impl From<Diagnostics> for CoreError {
    fn from(d: Diagnostics) -> Self {
        LanguageError::Invalid(d).into()
    }
}

impl From<CoreError> for PyErr {
    fn from(CoreError(e): CoreError) -> Self {
        use a2ml_core::Error;
        let message = e.to_string();
        match e {
            Error::Robot(_) => UrdfError::new_err(message),
            Error::Language(LanguageError::Invalid(d)) => Python::attach(|py| parse_error(py, &d)),
            Error::Language(LanguageError::Io { .. }) => PyOSError::new_err(message),
            Error::Output(_) => PyOSError::new_err(message),
            Error::Read(a2ml_core::output::ReadError::Io { .. }) => PyOSError::new_err(message),
            Error::Read(_) => PyValueError::new_err(message),
            Error::Kinematics(k) => match k {
                KinematicsError::Unreachable { .. } => UnreachableError::new_err(message),
                KinematicsError::JointOutOfLimits { .. } => JointLimitError::new_err(message),
                KinematicsError::Singular(_) => SingularityError::new_err(message),
                KinematicsError::NoConvergence { .. } | KinematicsError::NotAnalytic { .. } => {
                    ConvergenceError::new_err(message)
                }
                KinematicsError::NonFinite { .. } => PyValueError::new_err(message),
            },
            Error::Decompose(_) => DecomposeError::new_err(message),
            // No profile or trajectory API in Python yet; the base class until there is.
            Error::Profile(_) | Error::Trajectory(_) => A2mlError::new_err(message),
            Error::Solve(SolveError::Decompose(_)) => DecomposeError::new_err(message),
            // A rate passed to `plan` (the task's own is validated when parsed).
            Error::Solve(
                SolveError::InvalidRate { .. } | SolveError::InvalidAccelerationScale { .. },
            ) => PyValueError::new_err(message),
            Error::Solve(_) => PlanError::new_err(message),
        }
    }
}

/// A `ParseError` whose str is every diagnostic rendered, with the first
/// one's `line`, `column` (1-based) and `message`, `errors` as
/// `(line, column, message)` for all, and `path` (the file or None).
fn parse_error(py: Python<'_>, d: &Diagnostics) -> PyErr {
    let errors: Vec<(usize, usize, String)> = d
        .items
        .iter()
        .map(|item| {
            let (line, column) = d.line_col(item.span.start);
            (line, column, item.message.clone())
        })
        .collect();
    // The core never reports an empty list; if it did, point at the start.
    let (line, column, message) = errors.first().cloned().unwrap_or_else(|| (1, 1, d.to_string()));
    let err = ParseError::new_err(d.to_string());
    let value = err.value(py);
    let set = || -> PyResult<()> {
        value.setattr("line", line)?;
        value.setattr("column", column)?;
        value.setattr("message", message)?;
        value.setattr("errors", errors)?;
        value.setattr("path", d.path.as_deref())
    };
    match set() {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// An I/O error as Python raises it: `OSError(errno, strerror, filename)`,
/// which Python turns into `FileNotFoundError`, `PermissionError`, ...
fn os_error(py: Python<'_>, e: &std::io::Error, path: &Path) -> PyErr {
    let filename = path.to_string_lossy().into_owned();
    let Some(errno) = e.raw_os_error() else {
        return PyOSError::new_err(format!("cannot read {filename}: {e}"));
    };
    let strerror = py
        .import("os")
        .and_then(|os| os.call_method1("strerror", (errno,)))
        .and_then(|s| s.extract::<String>())
        .unwrap_or_else(|_| e.to_string());
    PyOSError::new_err((errno, strerror, filename))
}

/// A float64 numpy vector.
type Vector<'py> = Bound<'py, PyArray1<Real>>;
/// A float64 numpy matrix.
type Matrix<'py> = Bound<'py, PyArray2<Real>>;

/// Rotation matrices from Python must be orthonormal to this tolerance.
const ROTATION_TOL: Real = 1e-6;

/// `(7,)` or `(3, 3)`, as numpy prints shapes.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!("({})", shape.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ")),
    }
}

/// The values of an array-like of exactly `shape`, row-major, all finite.
fn read_array(value: &Bound<'_, PyAny>, name: &str, shape: &[usize]) -> PyResult<Vec<Real>> {
    let array = value.extract::<PyArrayLikeDyn<'_, Real, AllowTypeChange>>().map_err(|e| {
        let message = format!(
            "{name} must be an array of numbers of shape {}: {}",
            shape_text(shape),
            e.value(value.py())
        );
        if e.is_instance_of::<PyTypeError>(value.py()) {
            PyTypeError::new_err(message)
        } else {
            PyValueError::new_err(message)
        }
    })?;
    if array.shape() != shape {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape {}, got {}",
            shape_text(shape),
            shape_text(array.shape())
        )));
    }
    let values: Vec<Real> = array.as_array().iter().copied().collect();
    if !values.iter().all(|v| v.is_finite()) {
        return Err(PyValueError::new_err(format!("{name} contains NaN or infinity")));
    }
    Ok(values)
}

fn read_joints(value: &Bound<'_, PyAny>, name: &str) -> PyResult<JointVector> {
    Ok(JointVector::from_row_slice(&read_array(value, name, &[DOF])?))
}

fn read_vector3(value: &Bound<'_, PyAny>, name: &str) -> PyResult<Vector3> {
    Ok(Vector3::from_row_slice(&read_array(value, name, &[3])?))
}

fn read_rotation(value: &Bound<'_, PyAny>, name: &str) -> PyResult<Rotation3> {
    let m = Matrix3::from_row_slice(&read_array(value, name, &[3, 3])?);
    let error = (m.transpose() * m - Matrix3::identity()).amax();
    if error > ROTATION_TOL {
        return Err(PyValueError::new_err(format!(
            "{name} is not a rotation matrix: max |RᵀR - I| = {error:.3e} (tolerance {ROTATION_TOL:e})"
        )));
    }
    if m.determinant() < 0.0 {
        return Err(PyValueError::new_err(format!(
            "{name} is a reflection (determinant -1), not a rotation"
        )));
    }
    Ok(Rotation3::from_matrix_unchecked(m))
}

fn read_angle(value: Real, name: &str) -> PyResult<Real> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(PyValueError::new_err(format!("{name} must be finite, got {value}")))
    }
}

/// Any nalgebra matrix (they all index by `(row, column)`) as a 2-D array.
fn to_matrix<'py, M>(py: Python<'py>, m: &M, rows: usize, cols: usize) -> Matrix<'py>
where
    M: std::ops::Index<(usize, usize), Output = Real>,
{
    Array2::from_shape_fn((rows, cols), |(i, j)| m[(i, j)]).into_pyarray(py)
}

fn to_vector<'py>(py: Python<'py>, v: &[Real]) -> Vector<'py> {
    PyArray1::from_slice(py, v)
}

fn to_rotation<'py>(py: Python<'py>, r: &Rotation3) -> Matrix<'py> {
    to_matrix(py, r.matrix(), 3, 3)
}

/// The nearest solution as (7,), or every solution as (n, 7).
fn to_solutions<'py>(
    py: Python<'py>,
    solutions: &[JointVector],
    all_branches: bool,
) -> Bound<'py, PyAny> {
    if all_branches {
        Array2::from_shape_fn((solutions.len(), DOF), |(i, j)| solutions[i][j])
            .into_pyarray(py)
            .into_any()
    } else {
        // The core returns at least one solution or an error; nearest first.
        to_vector(py, solutions.first().map(|q| q.as_slice()).unwrap_or(&[])).into_any()
    }
}

/// A 7-DoF anthropomorphic arm read from a URDF; immutable.
///
/// Pickles as its URDF text (kept by the core model) and the chain options.
#[pyclass(frozen, module = "a2ml", name = "Robot")]
pub(crate) struct PyRobot {
    pub(crate) robot: a2ml_core::Robot,
    base: Option<String>,
    tip: Option<String>,
}

impl PyRobot {
    /// A task's robot, loaded with its `base` and `tip` (which it keeps, to pickle), releasing
    /// the GIL.
    pub(crate) fn of_task(py: Python<'_>, task: &a2ml_core::language::Task) -> PyResult<Self> {
        let robot = py.detach(|| task.load_robot(&RobotOptions::default()));
        let (base, tip) = (task.robot_base.clone(), task.robot_tip.clone());
        Ok(Self { robot: robot.map_err(CoreError::from)?, base, tip })
    }

    fn options(base: &Option<String>, tip: &Option<String>) -> RobotOptions {
        RobotOptions { base: base.clone(), tip: tip.clone(), ..RobotOptions::default() }
    }

    fn pose(&self, q: &Bound<'_, PyAny>) -> PyResult<kinematics::ArmPose> {
        Ok(kinematics::arm_pose(&self.robot, &read_joints(q, "q")?))
    }

    fn near(q_near: Option<&Bound<'_, PyAny>>) -> PyResult<Option<JointVector>> {
        q_near.map(|q| read_joints(q, "q_near")).transpose()
    }
}

#[pymethods]
impl PyRobot {
    /// Reads a URDF file; `base` and `tip` pick the chain when it is ambiguous.
    #[classmethod]
    #[pyo3(signature = (path, base=None, tip=None))]
    fn from_urdf(
        _cls: &Bound<'_, PyType>,
        path: PathBuf,
        base: Option<String>,
        tip: Option<String>,
    ) -> PyResult<Self> {
        let robot = a2ml_core::Robot::from_urdf_file_with(&path, &Self::options(&base, &tip))
            .map_err(CoreError::from)?;
        Ok(Self { robot, base, tip })
    }

    /// Reads a URDF document given as a string.
    #[classmethod]
    #[pyo3(signature = (text, base=None, tip=None))]
    fn from_urdf_string(
        _cls: &Bound<'_, PyType>,
        text: String,
        base: Option<String>,
        tip: Option<String>,
    ) -> PyResult<Self> {
        let robot = a2ml_core::Robot::from_urdf_str(&text, &Self::options(&base, &tip))
            .map_err(CoreError::from)?;
        Ok(Self { robot, base, tip })
    }

    /// Pickles as `Robot.from_urdf_string(urdf, base, tip)`.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let this = slf.get();
        let rebuild = slf.get_type().getattr("from_urdf_string")?;
        let args = (this.robot.urdf.as_str(), this.base.as_deref(), this.tip.as_deref())
            .into_pyobject(py)?;
        PyTuple::new(py, [rebuild, args.into_any()])
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let quoted = |s: &str| -> PyResult<String> { Ok(PyString::new(py, s).repr()?.to_string()) };
        Ok(format!(
            "Robot(name={}, base_link={}, tip_link={})",
            quoted(&self.robot.name)?,
            quoted(&self.robot.base_link)?,
            quoted(&self.robot.tip_link)?
        ))
    }

    /// URDF robot name.
    #[getter]
    fn name(&self) -> &str {
        &self.robot.name
    }

    /// Number of joints (always 7).
    #[getter]
    fn dof(&self) -> usize {
        DOF
    }

    /// Joint names, base to tip.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.robot.joint_names().into_iter().map(str::to_owned).collect()
    }

    /// Lower position limits (rad), shape (7,).
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> Vector<'py> {
        to_vector(py, self.robot.lower().as_slice())
    }

    /// Upper position limits (rad), shape (7,).
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> Vector<'py> {
        to_vector(py, self.robot.upper().as_slice())
    }

    /// Velocity limits (rad/s), shape (7,).
    #[getter]
    fn velocity_limits<'py>(&self, py: Python<'py>) -> Vector<'py> {
        to_vector(py, self.robot.velocity_limits().as_slice())
    }

    /// Spherical shoulder and wrist and no elbow offset.
    #[getter]
    fn is_srs(&self) -> bool {
        self.robot.structure.is_srs
    }

    /// Whether IK is closed-form (else damped Newton).
    #[getter]
    fn has_analytic_ik(&self) -> bool {
        self.robot.has_analytic_ik()
    }

    /// lu = |E - S| (m).
    #[getter]
    fn upper_arm_length(&self) -> Real {
        self.robot.upper_arm_length()
    }

    /// lf = |W - E| at the zero configuration (m).
    #[getter]
    fn forearm_length(&self) -> Real {
        self.robot.forearm_length()
    }

    /// Base link of the chain.
    #[getter]
    fn base_link(&self) -> &str {
        &self.robot.base_link
    }

    /// Tip link of the chain.
    #[getter]
    fn tip_link(&self) -> &str {
        &self.robot.tip_link
    }

    /// The hand frame {W} in {b} as a 4x4 homogeneous matrix.
    fn fk<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Matrix<'py>> {
        let frame = self.pose(q)?.hand_frame().to_homogeneous();
        Ok(to_matrix(py, &frame, 4, 4))
    }

    /// Shoulder, elbow and wrist centres in {b}.
    fn centers<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
        let pose = self.pose(q)?;
        let dict = PyDict::new(py);
        dict.set_item("shoulder", to_vector(py, pose.shoulder.as_slice()))?;
        dict.set_item("elbow", to_vector(py, pose.elbow.as_slice()))?;
        dict.set_item("wrist", to_vector(py, pose.wrist.as_slice()))?;
        Ok(dict)
    }

    /// J_ge (6x7): linear velocity of W, angular velocity of the hand.
    fn jacobian<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Matrix<'py>> {
        let j = kinematics::geometric_jacobian(&self.pose(q)?);
        Ok(to_matrix(py, &j, 6, DOF))
    }

    /// The CPSA state (pw, ow, swivel).
    fn cpsa<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<(Vector<'py>, Matrix<'py>, Real)> {
        let s = kinematics::cpsa_state(&self.robot, &self.pose(q)?).map_err(CoreError::from)?;
        Ok((to_vector(py, s.pw.as_slice()), to_rotation(py, &s.ow), s.swivel))
    }

    /// The HAT state (os, elbow, ow).
    fn hat<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<(Matrix<'py>, Real, Matrix<'py>)> {
        let s = kinematics::hat_state(&self.pose(q)?).map_err(CoreError::from)?;
        Ok((to_rotation(py, &s.shoulder_frame), s.elbow_angle, to_rotation(py, &s.ow)))
    }

    /// J_cs (7x7): q' to [Pw', ω_w, θsw'].
    fn cpsa_jacobian<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Matrix<'py>> {
        let j = kinematics::cpsa_jacobian(&self.robot, &self.pose(q)?).map_err(CoreError::from)?;
        Ok(to_matrix(py, &j, DOF, DOF))
    }

    /// J_tr (7x7): q' to [ω_s, θe', ω_w].
    fn hat_jacobian<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Matrix<'py>> {
        let j = kinematics::hat_jacobian(&self.pose(q)?).map_err(CoreError::from)?;
        Ok(to_matrix(py, &j, DOF, DOF))
    }

    /// Joints reaching a CPSA state: the in-limit solution nearest `q_near`,
    /// or all of them (nearest first) with `all_branches`.
    #[pyo3(signature = (pw, ow, swivel, q_near=None, all_branches=false))]
    fn ik_cpsa<'py>(
        &self,
        py: Python<'py>,
        pw: &Bound<'py, PyAny>,
        ow: &Bound<'py, PyAny>,
        swivel: Real,
        q_near: Option<&Bound<'py, PyAny>>,
        all_branches: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let target = CpsaState {
            pw: read_vector3(pw, "pw")?,
            ow: read_rotation(ow, "ow")?,
            swivel: read_angle(swivel, "swivel")?,
        };
        let near = Self::near(q_near)?;
        let solutions = py
            .detach(|| kinematics::ik_cpsa(&self.robot, &target, near.as_ref()))
            .map_err(CoreError::from)?;
        Ok(to_solutions(py, &solutions, all_branches))
    }

    /// Joints reaching a HAT state; as `ik_cpsa`.
    #[pyo3(signature = (os, elbow, ow, q_near=None, all_branches=false))]
    fn ik_hat<'py>(
        &self,
        py: Python<'py>,
        os: &Bound<'py, PyAny>,
        elbow: Real,
        ow: &Bound<'py, PyAny>,
        q_near: Option<&Bound<'py, PyAny>>,
        all_branches: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let target = HatState {
            shoulder_frame: read_rotation(os, "os")?,
            elbow_angle: read_angle(elbow, "elbow")?,
            ow: read_rotation(ow, "ow")?,
        };
        let near = Self::near(q_near)?;
        let solutions = py
            .detach(|| kinematics::ik_hat(&self.robot, &target, near.as_ref()))
            .map_err(CoreError::from)?;
        Ok(to_solutions(py, &solutions, all_branches))
    }

    /// The swivel angles at which (pw, ow) is reachable within the joint
    /// limits, as sorted disjoint (lower, upper) intervals of [-π, π].
    fn swivel_intervals(
        &self,
        py: Python<'_>,
        pw: &Bound<'_, PyAny>,
        ow: &Bound<'_, PyAny>,
    ) -> PyResult<Vec<(Real, Real)>> {
        let (pw, ow) = (read_vector3(pw, "pw")?, read_rotation(ow, "ow")?);
        let intervals = py
            .detach(|| kinematics::swivel_intervals(&self.robot, &pw, &ow))
            .map_err(CoreError::from)?;
        Ok(intervals.into_iter().map(|i| (i.lower, i.upper)).collect())
    }
}

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
