//! The exception tree under `a2ml.A2mlError` and the one mapping of core errors onto it
//! (polars' newtype `From`): every fallible binding returns `PyResult` through [`CoreError`].

use std::path::Path;

use a2ml_core::kinematics::KinematicsError;
use a2ml_core::language::{Diagnostics, LanguageError};
use a2ml_core::output::OutputError;
use a2ml_core::robot::RobotError;
use a2ml_core::solve::SolveError;
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyOSError, PyValueError};
use pyo3::prelude::*;

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
pub(crate) struct CoreError(a2ml_core::Error);

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
pub(crate) fn os_error(py: Python<'_>, e: &std::io::Error, path: &Path) -> PyErr {
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
