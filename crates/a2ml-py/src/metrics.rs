//! `a2ml.metrics` (the pure-Python module wraps these `_metrics_*` functions) and
//! `Plan.metrics()`: the human-likeness measures of the core's [`a2ml_core::metrics`], the
//! HAMP similarity indices and the HAMP handover planner.
//!
//! Per-frame measures cross as float64 numpy arrays (scores as floats, NaN where a frame
//! cannot be scored); the per-segment summaries as the same dicts `a2ml analyze --json`
//! prints, so the two agree by construction.

use std::path::{Path, PathBuf};

use a2ml_core::collision::CollisionScene;
use a2ml_core::math::Real;
use a2ml_core::metrics::pattern::{
    self, Hamp, connection_frequencies, connection_similarity, levenshtein, similarity,
};
use a2ml_core::metrics::rula::{RulaScores, table_a};
use a2ml_core::metrics::{self, Analysis, MetricsOptions, Span, SpanMetrics};
use a2ml_core::output::{self, ReadError, RecordedPlan};
use a2ml_core::robot::RobotOptions;
use a2ml_core::solve::hamp::{HampOptions, Handover, HandoverTarget, plan_handover};
use a2ml_core::trajectory::Trajectory;
use pyo3::exceptions::{PyOSError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::plan::{PyPlan, joint_rows};
use crate::{PlanError, PyRobot, UrdfError, read_joints, read_rotation, read_vector3, to_vector};

type Dict<'py> = Bound<'py, PyDict>;

fn read_error(e: ReadError) -> PyErr {
    match e {
        ReadError::Io { .. } => PyOSError::new_err(e.to_string()),
        other => PyValueError::new_err(other.to_string()),
    }
}

fn hamp(text: &str) -> PyResult<Hamp> {
    text.parse().map_err(|e: pattern::PatternError| PyValueError::new_err(e.to_string()))
}

/// A value as the JSON `a2ml analyze --json` prints, loaded by Python's `json`.
fn as_python<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| PyValueError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

fn score_column<'py>(
    py: Python<'py>,
    scores: &[Option<RulaScores>],
    pick: impl Fn(&RulaScores) -> u8,
) -> Bound<'py, numpy::PyArray1<Real>> {
    let values: Vec<Real> =
        scores.iter().map(|s| s.map_or(Real::NAN, |s| Real::from(pick(&s)))).collect();
    to_vector(py, &values)
}

/// The analysis as a dict: `frames` (arrays), `whole` and `segments` (summaries).
fn analysis_dict<'py>(py: Python<'py>, analysis: &Analysis) -> PyResult<Dict<'py>> {
    let f = &analysis.frames;
    let frames = PyDict::new(py);
    frames.set_item("t", to_vector(py, &f.speeds.times))?;
    frames.set_item("position_speed", to_vector(py, &f.speeds.position))?;
    frames.set_item("orientation_speed", to_vector(py, &f.speeds.orientation))?;
    frames.set_item("swivel_speed", to_vector(py, &f.speeds.swivel))?;
    frames.set_item("swivel", to_vector(py, &f.swivel))?;
    frames.set_item("rula", score_column(py, &f.rula, |s| s.table_a))?;
    frames.set_item("rula_sum", score_column(py, &f.rula, |s| s.sum))?;
    frames.set_item("upper_arm", score_column(py, &f.rula, |s| s.upper_arm))?;
    frames.set_item("lower_arm", score_column(py, &f.rula, |s| s.lower_arm))?;
    frames.set_item("wrist", score_column(py, &f.rula, |s| s.wrist))?;
    frames.set_item("wrist_twist", score_column(py, &f.rula, |s| s.wrist_twist))?;
    let angle = |pick: fn(&metrics::rula::RulaAngles) -> Real| {
        let values: Vec<Real> =
            f.rula_angles.iter().map(|a| a.as_ref().map_or(Real::NAN, pick)).collect();
        to_vector(py, &values)
    };
    frames.set_item("upper_arm_flexion", angle(|a| a.upper_arm_flexion))?;
    frames.set_item("upper_arm_abduction", angle(|a| a.upper_arm_abduction))?;
    frames.set_item("elbow_flexion", angle(|a| a.elbow_flexion))?;
    frames.set_item("wrist_flexion", angle(|a| a.wrist_flexion))?;
    frames.set_item("wrist_deviation", angle(|a| a.wrist_deviation))?;
    let out = PyDict::new(py);
    out.set_item("frames", frames)?;
    out.set_item("whole", as_python(py, &analysis.whole)?)?;
    let segments: Vec<&SpanMetrics> = analysis.segments.iter().collect();
    out.set_item("segments", as_python(py, &segments)?)?;
    out.set_item("singular_frames", f.singular_frames)?;
    Ok(out)
}

fn analyze_trajectory<'py>(
    py: Python<'py>,
    robot: &a2ml_core::Robot,
    trajectory: &Trajectory,
    spans: &[Span],
) -> PyResult<Dict<'py>> {
    let analysis =
        py.detach(|| metrics::analyze(robot, trajectory, spans, &MetricsOptions::default()));
    analysis_dict(py, &analysis)
}

/// `Plan.metrics()`: the analysis of a fresh plan, segments from its reports.
pub(crate) fn plan_metrics<'py>(
    py: Python<'py>,
    plan: &a2ml_core::solve::Plan,
    robot: &a2ml_core::Robot,
) -> PyResult<Dict<'py>> {
    analyze_trajectory(py, robot, &plan.trajectory, &Span::of_plan(plan))
}

fn read_plan(path: &Path) -> PyResult<RecordedPlan> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("mcap") => output::read_mcap(path).map_err(read_error),
        Some("csv") => output::read_csv(path).map_err(read_error),
        _ => Err(PyValueError::new_err(format!(
            "{}: give a plan written by a2ml: an .mcap or a .csv file",
            path.display()
        ))),
    }
}

/// The measures of a plan, or of the plan file (.mcap, .csv) at a path.
#[pyfunction]
#[pyo3(signature = (plan_or_path, robot=None))]
pub(crate) fn _metrics_analyze<'py>(
    py: Python<'py>,
    plan_or_path: &Bound<'py, PyAny>,
    robot: Option<Bound<'py, PyRobot>>,
) -> PyResult<Dict<'py>> {
    if let Ok(plan) = plan_or_path.cast::<PyPlan>() {
        let plan = plan.get();
        let own = plan.robot.bind(py);
        let robot_model = robot.as_ref().map_or(&own.get().robot, |r| &r.get().robot);
        return plan_metrics(py, &plan.plan, robot_model);
    }
    let path: PathBuf = plan_or_path.extract().map_err(|_| {
        PyTypeError::new_err("plan_or_path must be an a2ml.Plan or a path to an .mcap or .csv file")
    })?;
    let recorded = py.detach(|| read_plan(&path))?;
    let loaded;
    let robot_model = match (&robot, &recorded.urdf) {
        (Some(r), _) => &r.get().robot,
        (None, Some(urdf)) => {
            loaded = a2ml_core::Robot::from_urdf_str(urdf, &RobotOptions::default())
                .map_err(|e| UrdfError::new_err(format!("the attached URDF: {e}")))?;
            &loaded
        }
        (None, None) => {
            return Err(PyValueError::new_err(format!(
                "{}: no URDF attached: pass robot=",
                path.display()
            )));
        }
    };
    recorded.check_joints(&robot_model.joint_names()).map_err(read_error)?;
    let spans = Span::of_recorded(&recorded);
    analyze_trajectory(py, robot_model, &recorded.trajectory, &spans)
}

/// sim(h, s) (HAMP eq. 3).
#[pyfunction]
pub(crate) fn _metrics_similarity(h: &str, s: &str) -> PyResult<Real> {
    Ok(similarity(&hamp(h)?, &hamp(s)?))
}

/// Levenshtein distance over primitive tokens.
#[pyfunction]
pub(crate) fn _metrics_levenshtein(h: &str, s: &str) -> PyResult<usize> {
    Ok(levenshtein(&hamp(h)?, &hamp(s)?))
}

fn population(items: Vec<(String, Real)>) -> PyResult<Vec<(Hamp, Real)>> {
    items.into_iter().map(|(h, f)| Ok((hamp(&h)?, f))).collect()
}

/// simc(h, s) (HAMP eq. 4), f_h the target's share, f_L from `population`.
#[pyfunction]
pub(crate) fn _metrics_connection_similarity(
    h: &str,
    s: &str,
    target_share: Real,
    population_shares: Vec<(String, Real)>,
) -> PyResult<Real> {
    let frequencies = connection_frequencies(&population(population_shares)?);
    Ok(connection_similarity(&hamp(h)?, &hamp(s)?, target_share, &frequencies))
}

/// MPCSI (HAMP eqs. 5-6) of each candidate over the samples.
#[pyfunction]
pub(crate) fn _metrics_mpcsi(
    candidates: Vec<String>,
    samples: Vec<String>,
    population_shares: Vec<(String, Real)>,
) -> PyResult<Vec<Real>> {
    let candidates: Vec<Hamp> = candidates.iter().map(|h| hamp(h)).collect::<PyResult<_>>()?;
    let samples: Vec<Hamp> = samples.iter().map(|h| hamp(h)).collect::<PyResult<_>>()?;
    Ok(pattern::mpcsi(&candidates, &samples, &population(population_shares)?))
}

/// Fitts' T (s) for a travel of `amplitude` metres.
#[pyfunction]
pub(crate) fn _metrics_fitts_duration(amplitude: Real) -> PyResult<Real> {
    if !(amplitude.is_finite() && amplitude >= 0.0) {
        return Err(PyValueError::new_err(format!("amplitude must be ≥ 0 m, got {amplitude}")));
    }
    Ok(a2ml_core::decompose::FittsLaw::default().duration(amplitude))
}

/// RULA Table A.
#[pyfunction]
pub(crate) fn _metrics_rula_table_a(
    upper_arm: u8,
    lower_arm: u8,
    wrist: u8,
    wrist_twist: u8,
) -> PyResult<u8> {
    let valid = (1..=6).contains(&upper_arm)
        && (1..=3).contains(&lower_arm)
        && (1..=4).contains(&wrist)
        && (1..=2).contains(&wrist_twist);
    if !valid {
        return Err(PyValueError::new_err(
            "scores out of Table A: upper arm 1-6, lower arm 1-3, wrist 1-4, twist 1-2",
        ));
    }
    Ok(table_a(upper_arm, lower_arm, wrist, wrist_twist))
}

/// The HAMP handover planner from `start` to the hand pose (pw, ow[, swivel]).
#[pyfunction]
#[pyo3(signature = (robot, start, pw, ow, swivel=None, handover="pick_up", seed=0, rate=120.0))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _metrics_plan_handover<'py>(
    py: Python<'py>,
    robot: Bound<'py, PyRobot>,
    start: &Bound<'py, PyAny>,
    pw: &Bound<'py, PyAny>,
    ow: &Bound<'py, PyAny>,
    swivel: Option<Real>,
    handover: &str,
    seed: u64,
    rate: Real,
) -> PyResult<Dict<'py>> {
    let handover = match handover {
        "pick_up" => Handover::PickUp,
        "delivery" => Handover::Delivery,
        other => {
            return Err(PyValueError::new_err(format!(
                "unknown handover '{other}' (pick_up, delivery)"
            )));
        }
    };
    let start = read_joints(start, "start")?;
    let target =
        HandoverTarget { pw: read_vector3(pw, "pw")?, ow: read_rotation(ow, "ow")?, swivel };
    let options = HampOptions { handover, seed, rate, ..HampOptions::default() };
    let robot = &robot.get().robot;
    let planned = py
        .detach(|| plan_handover(robot, &start, &target, &CollisionScene::new(&[]), &options))
        .map_err(|e| PlanError::new_err(e.to_string()))?;
    let out = PyDict::new(py);
    out.set_item("t", to_vector(py, planned.trajectory.times()))?;
    out.set_item("q", joint_rows(py, planned.trajectory.positions()))?;
    out.set_item("qd", joint_rows(py, planned.trajectory.velocities()))?;
    out.set_item("phase1", planned.phase1.to_string())?;
    out.set_item("phase2", planned.phase2.to_string())?;
    out.set_item("duration", planned.duration)?;
    out.set_item("peak_time", planned.peak_time)?;
    out.set_item("travel", planned.travel)?;
    out.set_item("swivel", planned.swivel)?;
    out.set_item("swivel_window", planned.swivel_window)?;
    out.set_item("swivel_ratios", planned.swivel_ratios)?;
    out.set_item("duration_ratio", planned.duration_ratio)?;
    out.set_item("limit_violations", planned.limit_violations.len())?;
    out.set_item("clearance", planned.clearance.map(|c| c.distance))?;
    out.set_item("metrics", analyze_trajectory(py, robot, &planned.trajectory, &[])?)?;
    Ok(out)
}
