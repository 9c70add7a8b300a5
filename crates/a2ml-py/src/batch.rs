//! Kinematics over many configurations at once (`Robot.fk_many`, `jacobian_many`,
//! `cpsa_many`, `ik_cpsa_many`) and the per-call FK + Jacobian (`Robot.fk_jacobian`).
//!
//! A call from Python costs more in conversions than the core spends on FK, so these read
//! float64 arrays in place (any other array-like is converted once), write into arrays the
//! caller passes (`out=`) or into one array made for the result, and run the rows with the
//! GIL released, by the core's batched kernel (`kinematics::BatchedChain`: several rows side by
//! side). A batch of at least [`PARALLEL_ROWS`] rows is shared out in chunks between the
//! calling thread and the helper threads of [`a2ml_core::team`] that come while it runs (the
//! caller never waits for one that has not started): a row's result never depends on the
//! other rows, so the bits are the same as on one thread; a smaller batch runs on the calling
//! thread, where the hand-over would cost more than it saves.

use a2ml_core::kinematics::{self, BatchedChain, CpsaState, KinematicsError};
use a2ml_core::math::{DOF, JointVector, Matrix3, Real, Vector3};
use a2ml_core::team::team;
use numpy::npyffi::{NPY_ARRAY_WRITEABLE, objects::_PyArray_GET_ITEM_DATA};
use numpy::{
    AllowTypeChange, IntoPyArray, PyArrayDyn, PyArrayLikeDyn, PyArrayMethods, PyReadwriteArrayDyn,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::marker::Ungil;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};
use std::time::Duration;

use crate::convert::{not_numbers, read_joints, rotation_from, shape_text};
use crate::errors::CoreError;
use crate::robot::PyRobot;

/// Values per row of each batched array.
const FRAME: usize = kinematics::FRAME_VALUES;
const JACOBIAN: usize = kinematics::JACOBIAN_VALUES;

/// Rows from which a batch is split over two threads: at about 0.1 µs a row, 256 rows are
/// some 25 µs of work, well over the few microseconds a hand-over to another thread costs.
const PARALLEL_ROWS: usize = 256;

/// The cost of a row of each batched call, roughly (a 2-core x86_64 machine, one thread): what
/// tells a long batch, worth waking a sleeping helper before it starts ([`LONG_BATCH`]).
const FK_ROW: Duration = Duration::from_nanos(50);
const JACOBIAN_ROW: Duration = Duration::from_nanos(70);
const CPSA_ROW: Duration = Duration::from_nanos(70);
const IK_ROW: Duration = Duration::from_nanos(1_500);

/// A batch of at least this much work wakes a sleeping helper before it starts: the wake-up
/// costs the caller some 20 µs and the helper comes some 40 µs later (`a2ml_core::team`).
const LONG_BATCH: Duration = Duration::from_micros(300);

/// Output rows a batch writes, which [`in_chunks`] cuts at a row.
trait Split: Sized {
    /// The number of whole rows.
    fn rows(&self) -> usize;
    /// The first `row` rows and the rest.
    fn split_at_row(self, row: usize) -> (Self, Self);
}

/// One output array: `per_row` values a row.
struct Slots<'a> {
    values: &'a mut [Real],
    per_row: usize,
}

impl Split for Slots<'_> {
    fn rows(&self) -> usize {
        self.values.len() / self.per_row.max(1)
    }

    fn split_at_row(self, row: usize) -> (Self, Self) {
        let (a, b) = self.values.split_at_mut(row * self.per_row);
        (Slots { values: a, per_row: self.per_row }, Slots { values: b, per_row: self.per_row })
    }
}

/// The three arrays of `cpsa_many`, written in place: pw (3 a row), ow (9, row-major) and the
/// swivel angle (1).
struct CpsaSlots<'a> {
    pw: &'a mut [Real],
    ow: &'a mut [Real],
    swivel: &'a mut [Real],
}

impl Split for CpsaSlots<'_> {
    fn rows(&self) -> usize {
        (self.pw.len() / 3).min(self.ow.len() / 9).min(self.swivel.len())
    }

    fn split_at_row(self, row: usize) -> (Self, Self) {
        let (pw_a, pw_b) = self.pw.split_at_mut(3 * row);
        let (ow_a, ow_b) = self.ow.split_at_mut(9 * row);
        let (swivel_a, swivel_b) = self.swivel.split_at_mut(row);
        (
            CpsaSlots { pw: pw_a, ow: ow_a, swivel: swivel_a },
            CpsaSlots { pw: pw_b, ow: ow_b, swivel: swivel_b },
        )
    }
}

/// Rows a thread takes at a time from a split batch: a multiple of the kernel's lanes, some
/// 3–8 µs of work, so that a helper that comes late still finds some, and the calling thread
/// waits at most about that long for the helpers inside when it finds none left.
const CHUNK_ROWS: usize = 64;

/// `run(first_row, rows of q, rows of out)` over all of `q` and `out`; each call's answer, in
/// row order. Below [`PARALLEL_ROWS`] rows, one call on the calling thread; from there, the
/// batch is cut into chunks of [`CHUNK_ROWS`] rows that the calling thread and the helpers of
/// [`a2ml_core::team`] take in turn until none is left (which thread runs a chunk changes nothing:
/// a row's result never depends on the other rows).
fn in_chunks<R: Send, O: Split + Send>(
    q: &[Real],
    q_per_row: usize,
    row_cost: Duration,
    out: O,
    run: impl Fn(usize, &[Real], O) -> R + Sync,
) -> Vec<R> {
    let rows = (q.len() / q_per_row.max(1)).min(out.rows());
    if rows < PARALLEL_ROWS {
        return vec![run(0, q, out)];
    }
    let (mut chunks, mut q, mut out) = (Vec::new(), q, out);
    for first in (0..rows).step_by(CHUNK_ROWS) {
        let size = CHUNK_ROWS.min(rows - first);
        let (q_chunk, q_rest) = q.split_at(size * q_per_row);
        let (out_chunk, out_rest) = out.split_at_row(size);
        chunks.push((first, q_chunk, out_chunk));
        (q, out) = (q_rest, out_rest);
    }
    // Each chunk and its answer in a slot of its own, a chunk claimed by the counter: no two
    // threads ever want the same lock, so none waits on one.
    let chunks: Vec<_> = chunks.into_iter().map(|chunk| Mutex::new(Some(chunk))).collect();
    let answers: Vec<Mutex<Option<R>>> = chunks.iter().map(|_| Mutex::new(None)).collect();
    let next = AtomicUsize::new(0);
    // Every thread of the team runs this until no chunk is left. A poisoned lock means a
    // thread panicked while it held it: that panic is the one `Team::run` reports.
    let drain = || {
        loop {
            let index = next.fetch_add(1, Ordering::Relaxed);
            let (Some(chunk), Some(answer)) = (chunks.get(index), answers.get(index)) else {
                return;
            };
            let Some((first, q, out)) = chunk.lock().ok().and_then(|mut chunk| chunk.take()) else {
                return;
            };
            let result = run(first, q, out);
            if let Ok(mut answer) = answer.lock() {
                *answer = Some(result);
            }
        }
    };
    let long = row_cost.saturating_mul(u32::try_from(rows).unwrap_or(u32::MAX)) >= LONG_BATCH;
    team().run(&drain, long);
    answers
        .into_iter()
        .filter_map(|answer| answer.into_inner().unwrap_or_else(PoisonError::into_inner))
        .collect()
}

/// A float64 n-dimensional numpy array.
pub(crate) type Array<'py> = Bound<'py, PyArrayDyn<Real>>;

/// An array-like of shape (N, *row) read as N rows of `row`'s size, row-major: in place when
/// it is a C-contiguous float64 array, else converted once.
struct Rows<'py> {
    array: PyArrayLikeDyn<'py, Real, AllowTypeChange>,
    /// The values when the array is not C-contiguous.
    copied: Option<Vec<Real>>,
    count: usize,
}

impl Rows<'_> {
    fn values(&self) -> &[Real] {
        match &self.copied {
            Some(values) => values,
            None => self.array.as_slice().unwrap_or(&[]),
        }
    }
}

/// `(N, 7)` for a row shape `[7]`.
fn batch_shape_text(row: &[usize]) -> String {
    let rest: Vec<String> = row.iter().map(|n| n.to_string()).collect();
    format!("(N, {})", rest.join(", "))
}

/// The rows of `value`, which must have shape (N, *row) and finite entries; the error names
/// the argument and, for a non-finite entry, its row.
fn read_rows<'py>(value: &Bound<'py, PyAny>, name: &str, row: &[usize]) -> PyResult<Rows<'py>> {
    let like = value
        .extract::<PyArrayLikeDyn<'py, Real, AllowTypeChange>>()
        .map_err(|e| not_numbers(value, name, &batch_shape_text(row), &e))?;
    let shape = like.shape();
    if shape.len() != row.len() + 1 || shape[1..] != *row {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape {}, got {}",
            batch_shape_text(row),
            shape_text(shape)
        )));
    }
    let count = shape[0];
    let copied = (!like.is_c_contiguous()).then(|| like.as_array().iter().copied().collect());
    let rows = Rows { array: like, copied, count };
    let size: usize = row.iter().product();
    if let Some(bad) = rows.values().iter().position(|v| !v.is_finite()) {
        let at = bad.checked_div(size).unwrap_or(0);
        return Err(PyValueError::new_err(format!("{name}[{at}] contains NaN or infinity")));
    }
    Ok(rows)
}

/// The array a result is written into: the caller's `out` (float64, C-contiguous, writeable,
/// of exactly `shape`) or a new one.
fn output<'py>(
    py: Python<'py>,
    out: Option<&Bound<'py, PyAny>>,
    name: &str,
    shape: &[usize],
) -> PyResult<Array<'py>> {
    let Some(out) = out else {
        return Ok(PyArrayDyn::zeros(py, shape, false));
    };
    let array = out.cast::<PyArrayDyn<Real>>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{name} must be a float64 numpy array of shape {}",
            shape_text(shape)
        ))
    })?;
    if array.shape() != shape {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape {}, got {}",
            shape_text(shape),
            shape_text(array.shape())
        )));
    }
    if !array.is_c_contiguous() {
        return Err(PyValueError::new_err(format!("{name} must be C-contiguous")));
    }
    Ok(array.clone())
}

/// Calls of this module running with the GIL released while they hold borrows of numpy arrays
/// (the batched ones, [`detached`]). While none does, a per-call write into an `out` array,
/// made with the GIL held and no Python code running, overlaps no Rust borrow of this module,
/// so it skips rust-numpy's borrow tracking (a shared table entered and left per array).
/// Process-wide because the arrays are.
static DETACHED: AtomicUsize = AtomicUsize::new(0);

/// Counts a call in [`DETACHED`] while it lives.
struct Detached;

impl Detached {
    fn enter() -> Self {
        DETACHED.fetch_add(1, Ordering::SeqCst);
        Self
    }
}

impl Drop for Detached {
    fn drop(&mut self) {
        DETACHED.fetch_sub(1, Ordering::SeqCst);
    }
}

/// `f` with the GIL released, counted in [`DETACHED`]: every call of this module that holds
/// numpy borrows while detached goes through here.
fn detached<T: Ungil>(py: Python<'_>, f: impl Ungil + FnOnce() -> T) -> T {
    let _counted = Detached::enter();
    py.detach(f)
}

/// `values` copied into `array` (float64, C-contiguous, of their length: [`output`]'s), if it
/// can be done without rust-numpy's borrow tracking: no detached call of this module running
/// (none then holds a borrow of any array), the array writeable. False when not, and nothing
/// is written. Another extension that writes or reads the array with the GIL released (as
/// numpy's own loops may) is not seen, as it is not by rust-numpy either unless it uses it.
#[allow(unsafe_code)]
fn write_untracked(array: &Array<'_>, values: &[Real]) -> bool {
    if DETACHED.load(Ordering::SeqCst) != 0 {
        return false;
    }
    // SAFETY: the pointer is a live array's (the bound reference keeps it).
    let flags = unsafe { (*_PyArray_GET_ITEM_DATA(array.as_array_ptr())).flags };
    if flags & NPY_ARRAY_WRITEABLE == 0 {
        return false;
    }
    // SAFETY: the GIL is held and no Python code runs before the copy ends, so no Python code
    // touches the array meanwhile; no Rust borrow of it is live: this call holds none, and a
    // call of this module holding one while detached would be counted in DETACHED.
    match unsafe { array.as_slice_mut() } {
        Ok(slots) if slots.len() == values.len() => {
            slots.copy_from_slice(values);
            true
        }
        _ => false,
    }
}

/// Borrows `array` for writing; an `out` that is not writeable or shares memory with an input
/// is refused.
fn writer<'py>(array: &Array<'py>, name: &str) -> PyResult<PyReadwriteArrayDyn<'py, Real>> {
    array.try_readwrite().map_err(|e| {
        PyValueError::new_err(format!(
            "{name} cannot be written ({e}): pass a writeable array \
             that shares no memory with the inputs"
        ))
    })
}

/// The writer's values: [`output`] arrays are C-contiguous.
fn slots<'a>(writer: &'a mut PyReadwriteArrayDyn<'_, Real>) -> &'a mut [Real] {
    writer.as_slice_mut().unwrap_or(&mut [])
}

/// `values` (row-major, of `shape`) written into the caller's `out`, or as a new array: made
/// from the values directly, which costs less than a zeroed array borrowed for writing.
fn emit<'py>(
    py: Python<'py>,
    out: Option<&Bound<'py, PyAny>>,
    name: &str,
    shape: &[usize],
    values: &[Real],
) -> PyResult<Array<'py>> {
    if out.is_none() {
        let array = numpy::ndarray::ArrayD::from_shape_vec(shape, values.to_vec())
            .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
        return Ok(array.into_pyarray(py));
    }
    let array = output(py, out, name, shape)?;
    if !write_untracked(&array, values) {
        slots(&mut writer(&array, name)?).copy_from_slice(values);
    }
    Ok(array)
}

impl PyRobot {
    /// `q` as one row of joint values (7, finite).
    fn row(q: &Bound<'_, PyAny>) -> PyResult<[Real; DOF]> {
        let q = read_joints(q, "q")?;
        Ok(std::array::from_fn(|k| q[k]))
    }

    /// The hand frame {W} at `q` (4x4), written into `out` when given: the batched kernel's
    /// steps on one lane (`BatchedChain::hand_frame`), so a row of `fk_many` to the bit.
    pub(crate) fn frame_into<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Array<'py>> {
        let mut frame = [0.0; FRAME];
        self.chain.hand_frame(&Self::row(q)?, &mut frame);
        emit(py, out, "out", &[4, 4], &frame)
    }

    /// J_ge at `q` (6x7), written into `out` when given; as [`Self::frame_into`].
    pub(crate) fn jacobian_into<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Array<'py>> {
        let (mut frame, mut jacobian) = ([0.0; FRAME], [0.0; JACOBIAN]);
        self.chain.hand_frame_and_jacobian(&Self::row(q)?, &mut frame, &mut jacobian);
        emit(py, out, "out", &[6, DOF], &jacobian)
    }
}

/// A core error of row `row`, as the exception the per-call method raises, its message led
/// by the row.
fn row_error(py: Python<'_>, row: usize, e: KinematicsError) -> PyErr {
    let err = PyErr::from(CoreError::from(e));
    let message = format!("row {row}: {}", err.value(py));
    PyErr::from_type(err.get_type(py), message)
}

/// The per-row outcome of an IK batch.
#[derive(Clone, Copy, PartialEq, Eq)]
enum OnError {
    /// The first failing row raises its exception.
    Raise,
    /// A failing row is NaN.
    Nan,
}

impl OnError {
    fn parse(text: &str) -> PyResult<Self> {
        match text {
            "raise" => Ok(Self::Raise),
            "nan" => Ok(Self::Nan),
            other => Err(PyValueError::new_err(format!(
                "on_error must be \"raise\" or \"nan\", got {other:?}"
            ))),
        }
    }
}

impl PyRobot {
    /// `kernel` over the rows of `q` (N, 7), each writing one row of shape `row` into `out`
    /// (or a new (N, *row) array), with the GIL released: the input is read in place and the
    /// kernel writes straight into the output array. `row_cost`: a row's time, roughly.
    fn each_row<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
        row: &[usize],
        row_cost: Duration,
        kernel: impl Fn(&BatchedChain, &[Real], &mut [Real]) + Sync,
    ) -> PyResult<Array<'py>> {
        let rows = read_rows(q, "q", &[DOF])?;
        let shape: Vec<usize> = std::iter::once(rows.count).chain(row.iter().copied()).collect();
        let result = output(py, out, "out", &shape)?;
        let mut guard = writer(&result, "out")?;
        let (values, slots) = (rows.values(), slots(&mut guard));
        let per_row = row.iter().product();
        detached(py, || {
            in_chunks(values, DOF, row_cost, Slots { values: slots, per_row }, |_, q, out| {
                kernel(&self.chain, q, out.values)
            })
        });
        drop(guard);
        Ok(result)
    }
}

#[pymethods]
impl PyRobot {
    /// The hand frame {W} (4x4) and J_ge (6x7) at `q` from one FK, written into
    /// `frame_out` and `jacobian_out` when given.
    #[pyo3(signature = (q, frame_out=None, jacobian_out=None))]
    fn fk_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame_out: Option<&Bound<'py, PyAny>>,
        jacobian_out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(Array<'py>, Array<'py>)> {
        let (mut frame, mut jacobian) = ([0.0; FRAME], [0.0; JACOBIAN]);
        self.chain.hand_frame_and_jacobian(&Self::row(q)?, &mut frame, &mut jacobian);
        Ok((
            emit(py, frame_out, "frame_out", &[4, 4], &frame)?,
            emit(py, jacobian_out, "jacobian_out", &[6, DOF], &jacobian)?,
        ))
    }

    /// The hand frame {W} at each row of `q` (N, 7), as (N, 4, 4).
    #[pyo3(signature = (q, out=None))]
    fn fk_many<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Array<'py>> {
        self.each_row(py, q, out, &[4, 4], FK_ROW, BatchedChain::hand_frames)
    }

    /// J_ge at each row of `q` (N, 7), as (N, 6, 7).
    #[pyo3(signature = (q, out=None))]
    fn jacobian_many<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Array<'py>> {
        self.each_row(py, q, out, &[6, DOF], JACOBIAN_ROW, BatchedChain::jacobians)
    }

    /// The CPSA state at each row of `q` (N, 7): pw (N, 3), ow (N, 3, 3), swivel (N,), written
    /// into `out = (pw, ow, swivel)` when given.
    #[pyo3(signature = (q, out=None))]
    fn cpsa_many<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(Array<'py>, Array<'py>, Array<'py>)> {
        let rows = read_rows(q, "q", &[DOF])?;
        let n = rows.count;
        let outs = out
            .map(|out| {
                out.extract::<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)>().map_err(
                    |_| {
                        PyTypeError::new_err(
                            "out must be a tuple (pw, ow, swivel) of three float64 arrays",
                        )
                    },
                )
            })
            .transpose()?;
        let (pw_out, ow_out, swivel_out) = match &outs {
            Some((pw, ow, swivel)) => (Some(pw), Some(ow), Some(swivel)),
            None => (None, None, None),
        };
        let (pw, ow, swivel) = (
            output(py, pw_out, "out[0] (pw)", &[n, 3])?,
            output(py, ow_out, "out[1] (ow)", &[n, 3, 3])?,
            output(py, swivel_out, "out[2] (swivel)", &[n])?,
        );
        let (mut pw_guard, mut ow_guard, mut swivel_guard) = (
            writer(&pw, "out[0] (pw)")?,
            writer(&ow, "out[1] (ow)")?,
            writer(&swivel, "out[2] (swivel)")?,
        );
        let values = rows.values();
        let outputs = CpsaSlots {
            pw: slots(&mut pw_guard),
            ow: slots(&mut ow_guard),
            swivel: slots(&mut swivel_guard),
        };
        // Each row written straight into the three arrays; the first failing row is reported.
        let chunks = detached(py, || {
            in_chunks(values, DOF, CPSA_ROW, outputs, |first, q, out| {
                let failed = self.chain.cpsa_values(&self.robot, q, out.pw, out.ow, out.swivel);
                failed.map(|(row, e)| (first + row, e))
            })
        });
        if let Some((row, e)) = chunks.into_iter().flatten().next() {
            return Err(row_error(py, row, e));
        }
        drop((pw_guard, ow_guard, swivel_guard));
        Ok((pw, ow, swivel))
    }

    /// The in-limit IK solution of each CPSA state (pw (N, 3), ow (N, 3, 3), swivel (N,))
    /// nearest `q_near` ((N, 7), one (7,) for every row, or the middle of the ranges), as
    /// (N, 7); a row without one raises (`on_error="raise"`) or is NaN (`"nan"`).
    #[pyo3(signature = (pw, ow, swivel, q_near=None, out=None, on_error="raise"))]
    #[allow(clippy::too_many_arguments)]
    fn ik_cpsa_many<'py>(
        &self,
        py: Python<'py>,
        pw: &Bound<'py, PyAny>,
        ow: &Bound<'py, PyAny>,
        swivel: &Bound<'py, PyAny>,
        q_near: Option<&Bound<'py, PyAny>>,
        out: Option<&Bound<'py, PyAny>>,
        on_error: &str,
    ) -> PyResult<Array<'py>> {
        let on_error = OnError::parse(on_error)?;
        let pw = read_rows(pw, "pw", &[3])?;
        let n = pw.count;
        let ow = read_rows(ow, "ow", &[3, 3])?;
        let swivel = read_rows(swivel, "swivel", &[])?;
        for (name, count) in [("ow", ow.count), ("swivel", swivel.count)] {
            if count != n {
                return Err(PyValueError::new_err(format!(
                    "{name} has {count} rows, pw has {n}: one state per row"
                )));
            }
        }
        // One q_near for every row, or one per row.
        let per_row = |value: &Bound<'py, PyAny>| {
            value
                .extract::<PyArrayLikeDyn<'py, Real, AllowTypeChange>>()
                .is_ok_and(|a| a.ndim() == 2)
        };
        let (near_one, near_rows) = match q_near {
            None => (None, None),
            Some(value) if per_row(value) => {
                let rows = read_rows(value, "q_near", &[DOF])?;
                if rows.count != n {
                    return Err(PyValueError::new_err(format!(
                        "q_near has {} rows, pw has {n}: one per row, or one of shape (7,)",
                        rows.count
                    )));
                }
                (None, Some(rows))
            }
            Some(value) => (Some(read_joints(value, "q_near")?), None),
        };
        // Rotations are checked like the per-call method's, with the GIL, before any IK.
        let rotations = ow
            .values()
            .chunks_exact(9)
            .enumerate()
            .map(|(i, m)| rotation_from(Matrix3::from_row_slice(m), &format!("ow[{i}]")))
            .collect::<PyResult<Vec<_>>>()?;
        let result = output(py, out, "out", &[n, DOF])?;
        let mut guard = writer(&result, "out")?;
        let out = slots(&mut guard);
        let (pw, swivel) = (pw.values(), swivel.values());
        let near_values = near_rows.as_ref().map(|r| r.values());
        // The first failing row of each chunk, in row order.
        let chunks = detached(py, || {
            in_chunks(pw, 3, IK_ROW, Slots { values: out, per_row: DOF }, |first, _, out| {
                for (q, i) in out.values.chunks_exact_mut(DOF).zip(first..) {
                    let target = CpsaState {
                        pw: Vector3::from_column_slice(&pw[3 * i..3 * i + 3]),
                        ow: rotations[i],
                        swivel: swivel[i],
                    };
                    let near = near_values
                        .map(|v| JointVector::from_column_slice(&v[DOF * i..DOF * i + DOF]))
                        .or(near_one);
                    // The nearest solution alone: ik_cpsa's first, without the others. Without
                    // a q_near, ik_cpsa itself: a numerical arm then tries its guesses first.
                    let solved = match near {
                        Some(near) => kinematics::ik_cpsa_nearest(&self.robot, &target, &near),
                        None => kinematics::ik_cpsa(&self.robot, &target, None).and_then(|s| {
                            s.into_iter().next().ok_or(KinematicsError::NoConvergence {
                                residual: Real::INFINITY,
                                starts: 0,
                            })
                        }),
                    };
                    match solved {
                        Ok(solution) => q.copy_from_slice(solution.as_slice()),
                        Err(e) if on_error == OnError::Raise => return Some((i, e)),
                        Err(_) => q.fill(Real::NAN),
                    }
                }
                None
            })
        });
        if let Some((row, e)) = chunks.into_iter().flatten().next() {
            return Err(row_error(py, row, e));
        }
        drop(guard);
        Ok(result)
    }
}
