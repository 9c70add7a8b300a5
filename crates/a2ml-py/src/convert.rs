//! Conversions between numpy arrays and the core's nalgebra values: inputs are checked for
//! shape, finiteness and (rotations) orthonormality, with the argument's name in the error.

use a2ml_core::math::{DOF, JointVector, Matrix3, Real, Rotation3, Vector3};
use numpy::ndarray::Array2;
use numpy::{
    AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayLikeDyn, PyArrayMethods,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// A float64 numpy vector.
pub(crate) type Vector<'py> = Bound<'py, PyArray1<Real>>;
/// A float64 numpy matrix.
pub(crate) type Matrix<'py> = Bound<'py, PyArray2<Real>>;

/// Rotation matrices from Python must be orthonormal to this tolerance.
const ROTATION_TOL: Real = 1e-6;

/// `(7,)` or `(3, 3)`, as numpy prints shapes.
pub(crate) fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!("({})", shape.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ")),
    }
}

/// The values of an array-like of exactly `shape`, row-major, all finite.
pub(crate) fn read_array(
    value: &Bound<'_, PyAny>,
    name: &str,
    shape: &[usize],
) -> PyResult<Vec<Real>> {
    let array = value
        .extract::<PyArrayLikeDyn<'_, Real, AllowTypeChange>>()
        .map_err(|e| not_numbers(value, name, &shape_text(shape), &e))?;
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

/// Joints from a (7,) array-like. A float64 numpy vector, what callers in a loop pass, is
/// read element by element in place: no conversion, no copy, no borrow to register.
pub(crate) fn read_joints(value: &Bound<'_, PyAny>, name: &str) -> PyResult<JointVector> {
    if let Ok(array) = value.cast::<PyArray1<Real>>() {
        if array.len() == DOF {
            let q = JointVector::from_fn(|i, _| array.get_owned([i]).unwrap_or(Real::NAN));
            if !q.iter().all(|v| v.is_finite()) {
                return Err(PyValueError::new_err(format!("{name} contains NaN or infinity")));
            }
            return Ok(q);
        }
    }
    Ok(JointVector::from_row_slice(&read_array(value, name, &[DOF])?))
}

pub(crate) fn read_vector3(value: &Bound<'_, PyAny>, name: &str) -> PyResult<Vector3> {
    Ok(Vector3::from_row_slice(&read_array(value, name, &[3])?))
}

pub(crate) fn read_rotation(value: &Bound<'_, PyAny>, name: &str) -> PyResult<Rotation3> {
    rotation_from(Matrix3::from_row_slice(&read_array(value, name, &[3, 3])?), name)
}

/// `m` as a rotation if it is orthonormal (to `ROTATION_TOL`) with determinant +1.
pub(crate) fn rotation_from(m: Matrix3, name: &str) -> PyResult<Rotation3> {
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

pub(crate) fn read_angle(value: Real, name: &str) -> PyResult<Real> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(PyValueError::new_err(format!("{name} must be finite, got {value}")))
    }
}

/// Any nalgebra matrix (they all index by `(row, column)`) as a 2-D array.
pub(crate) fn to_matrix<'py, M>(py: Python<'py>, m: &M, rows: usize, cols: usize) -> Matrix<'py>
where
    M: std::ops::Index<(usize, usize), Output = Real>,
{
    Array2::from_shape_fn((rows, cols), |(i, j)| m[(i, j)]).into_pyarray(py)
}

pub(crate) fn to_vector<'py>(py: Python<'py>, v: &[Real]) -> Vector<'py> {
    PyArray1::from_slice(py, v)
}

pub(crate) fn to_rotation<'py>(py: Python<'py>, r: &Rotation3) -> Matrix<'py> {
    to_matrix(py, r.matrix(), 3, 3)
}

/// The nearest solution as (7,), or every solution as (n, 7).
pub(crate) fn to_solutions<'py>(
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

/// The error for `value` that numpy could not read as an array of numbers of `shape` (its
/// text): a `TypeError` where numpy raised one (not array-like at all), else a `ValueError`.
pub(crate) fn not_numbers(value: &Bound<'_, PyAny>, name: &str, shape: &str, e: &PyErr) -> PyErr {
    let message =
        format!("{name} must be an array of numbers of shape {shape}: {}", e.value(value.py()));
    if e.is_instance_of::<PyTypeError>(value.py()) {
        PyTypeError::new_err(message)
    } else {
        PyValueError::new_err(message)
    }
}
