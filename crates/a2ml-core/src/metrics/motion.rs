//! The measures of one motion: per frame (element speeds, primitives, RULA) and per span of
//! time (a segment or the whole plan), computed from the robot and a trajectory alone, so a
//! fresh plan and one read back from disk give the same numbers.

use super::fitts::{FittsCheck, fitts_check};
use super::pattern::{ElementSpeeds, PatternOptions, Phases, extract};
use super::rula::{RulaAngles, RulaOptions, RulaScores, rula_angles};
use super::smoothness::{path_normalised_jerk, speed_peaks};
use crate::decompose::FittsLaw;
use crate::kinematics::{arm_pose, cpsa_jacobian, cpsa_state, geometric_jacobian};
use crate::math::{JointVector, Real, Vector3};
use crate::output::RecordedPlan;
use crate::robot::Robot;
use crate::solve::Plan;
use crate::trajectory::Trajectory;

/// Settings of every measure.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct MetricsOptions {
    /// When an element counts as moving.
    pub pattern: PatternOptions,
    /// RULA's project choices.
    pub rula: RulaOptions,
    /// Fitts' law for the duration check.
    pub fitts: FittsLaw,
}

/// The per-frame measures of a trajectory, one entry per sample.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FrameMetrics {
    /// Element speeds at each sample (from q' through the Jacobians, so exact for the
    /// trajectory's own velocities).
    pub speeds: ElementSpeeds,
    /// Pw per sample in {b} (m).
    pub wrist: Vec<Vector3>,
    /// q per sample (rad).
    pub joints: Vec<JointVector>,
    /// θsw per sample (rad); NaN where the swivel angle is undefined.
    pub swivel: Vec<Real>,
    /// RULA angles per sample; `None` where the arm is straight.
    pub rula_angles: Vec<Option<RulaAngles>>,
    /// RULA scores per sample; `None` where the arm is straight.
    pub rula: Vec<Option<RulaScores>>,
    /// Samples where the swivel angle or the arm plane is undefined.
    pub singular_frames: usize,
}

/// The per-frame measures of `trajectory` on `robot`.
pub fn frame_metrics(
    robot: &Robot,
    trajectory: &Trajectory,
    options: &RulaOptions,
) -> FrameMetrics {
    let n = trajectory.len();
    let mut frames = FrameMetrics {
        speeds: ElementSpeeds { times: trajectory.times().to_vec(), ..ElementSpeeds::default() },
        wrist: Vec::with_capacity(n),
        joints: trajectory.positions().to_vec(),
        swivel: Vec::with_capacity(n),
        rula_angles: Vec::with_capacity(n),
        rula: Vec::with_capacity(n),
        singular_frames: 0,
    };
    for (q, qd) in trajectory.positions().iter().zip(trajectory.velocities()) {
        let pose = arm_pose(robot, q);
        let twist = geometric_jacobian(&pose) * qd;
        frames.speeds.position.push(twist.fixed_rows::<3>(0).norm());
        frames.speeds.orientation.push(twist.fixed_rows::<3>(3).norm());
        let swivel = cpsa_state(robot, &pose).map(|s| s.swivel);
        let swivel_rate = cpsa_jacobian(robot, &pose).map(|j| (j.row(6) * qd)[0].abs());
        if swivel.is_err() {
            frames.singular_frames += 1;
        }
        frames.swivel.push(swivel.unwrap_or(Real::NAN));
        frames.speeds.swivel.push(swivel_rate.unwrap_or(Real::NAN));
        frames.wrist.push(pose.wrist);
        let angles = rula_angles(robot, &pose, q[4], options).ok();
        frames.rula.push(angles.map(|a| super::rula::scores(&a, options)));
        frames.rula_angles.push(angles);
    }
    frames
}

/// A stretch of a motion to summarise: a segment, or the whole of it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Span {
    /// What it is: `action/segment` or `whole`.
    pub label: String,
    /// Start (s).
    pub start: Real,
    /// End (s).
    pub end: Real,
}

impl Span {
    /// One span per segment of `plan`, labelled `action/segment` (1-based).
    pub fn of_plan(plan: &Plan) -> Vec<Span> {
        plan.segments
            .iter()
            .map(|s| Span {
                label: format!("{}/{}", s.action, s.segment + 1),
                start: s.start,
                end: s.end,
            })
            .collect()
    }

    /// One span per segment record of a plan read back from a file.
    pub fn of_recorded(recorded: &RecordedPlan) -> Vec<Span> {
        recorded
            .segments
            .iter()
            .map(|s| Span {
                label: format!("{}/{}", s.action, s.segment + 1),
                start: s.start,
                end: s.end,
            })
            .collect()
    }
}

/// The shape of a speed profile: when it peaks and how symmetric it is.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BellShape {
    /// Highest speed (units of the profile).
    pub peak: Real,
    /// Time of the peak over the span's duration (0.5 for a symmetric bell).
    pub peak_time_ratio: Real,
    /// 1 - Σ|s(t) - s(T - t)| / Σ(s(t) + s(T - t)) over the samples: 1 for a profile
    /// symmetric about the span's middle, 0 for one with all its speed on one side.
    pub symmetry: Real,
}

/// The bell-shape measures of `speeds` sampled at `times`.
pub fn bell_shape(times: &[Real], speeds: &[Real]) -> BellShape {
    let n = times.len().min(speeds.len());
    if n == 0 {
        return BellShape { peak: 0.0, peak_time_ratio: 0.0, symmetry: 1.0 };
    }
    let k = (0..n).max_by(|&a, &b| speeds[a].total_cmp(&speeds[b])).unwrap_or(0);
    let duration = times[n - 1] - times[0];
    let (mut difference, mut total) = (0.0, 0.0);
    for i in 0..n {
        let (a, b) = (speeds[i], speeds[n - 1 - i]);
        difference += (a - b).abs();
        total += a + b;
    }
    BellShape {
        peak: speeds[k],
        peak_time_ratio: if duration > 0.0 { (times[k] - times[0]) / duration } else { 0.0 },
        symmetry: if total > 0.0 { 1.0 - difference / total } else { 1.0 },
    }
}

/// Mean and maximum of a score over the frames where it is defined.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ScoreSummary {
    /// Mean.
    pub mean: Real,
    /// Maximum.
    pub max: u8,
}

fn summary(scores: impl Iterator<Item = u8>) -> Option<ScoreSummary> {
    let (mut sum, mut count, mut max) = (0.0, 0usize, 0u8);
    for s in scores {
        sum += Real::from(s);
        count += 1;
        max = max.max(s);
    }
    (count > 0).then(|| ScoreSummary { mean: sum / count as Real, max })
}

/// The measures of one span.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SpanMetrics {
    /// The span.
    pub span: Span,
    /// Its samples: first and last index into the trajectory.
    pub frames: (usize, usize),
    /// Patterns (whole and per phase) and R_Φ, thresholds relative to this span's speeds.
    pub patterns: Phases,
    /// RULA Table A over the span; `None` if no frame could be scored.
    pub rula: Option<ScoreSummary>,
    /// The paper's sum UA + LA + W over the span.
    pub rula_sum: Option<ScoreSummary>,
    /// The wrist speed |Pw'|'s bell shape (m/s).
    pub wrist_speed: BellShape,
    /// The span's duration against Fitts' law for the wrist's travel.
    pub fitts: FittsCheck,
    /// Normalised jerk of the wrist path.
    pub wrist_jerk: Real,
    /// Normalised jerk of the joint path.
    pub joint_jerk: Real,
    /// Peaks of the wrist speed (above 5 % of its maximum, separated by 20 % dips).
    pub speed_peaks: usize,
}

/// The samples of `times` within [start, end] (at least one).
fn frame_range(times: &[Real], start: Real, end: Real) -> (usize, usize) {
    let tol = 1e-9;
    let first = times.partition_point(|&t| t < start - tol).min(times.len() - 1);
    let last = times.partition_point(|&t| t <= end + tol).saturating_sub(1).max(first);
    (first, last)
}

fn slice_speeds(speeds: &ElementSpeeds, first: usize, last: usize) -> ElementSpeeds {
    ElementSpeeds {
        times: speeds.times[first..=last].to_vec(),
        position: speeds.position[first..=last].to_vec(),
        orientation: speeds.orientation[first..=last].to_vec(),
        swivel: speeds.swivel[first..=last].to_vec(),
    }
}

/// The measures of `span` from the frame measures.
pub fn span_metrics(frames: &FrameMetrics, span: &Span, options: &MetricsOptions) -> SpanMetrics {
    let (first, last) = frame_range(&frames.speeds.times, span.start, span.end);
    let speeds = slice_speeds(&frames.speeds, first, last);
    let scored = || frames.rula[first..=last].iter().flatten();
    let amplitude = (frames.wrist[last] - frames.wrist[first]).norm();
    let duration = speeds.times[speeds.len() - 1] - speeds.times[0];
    SpanMetrics {
        span: span.clone(),
        frames: (first, last),
        patterns: extract(&speeds, &options.pattern),
        rula: summary(scored().map(|s| s.table_a)),
        rula_sum: summary(scored().map(|s| s.sum)),
        wrist_speed: bell_shape(&speeds.times, &speeds.position),
        fitts: fitts_check(&options.fitts, amplitude, duration),
        wrist_jerk: path_normalised_jerk(&speeds.times, &frames.wrist[first..=last]),
        joint_jerk: path_normalised_jerk(&speeds.times, &frames.joints[first..=last]),
        speed_peaks: speed_peaks(&speeds.position),
    }
}

/// Every measure of a motion: per frame, per span and for the whole of it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Analysis {
    /// Per-frame measures.
    pub frames: FrameMetrics,
    /// The whole motion.
    pub whole: SpanMetrics,
    /// Each span asked for (the plan's segments).
    pub segments: Vec<SpanMetrics>,
}

/// Analyses `trajectory` on `robot`, the whole motion and each of `spans`.
pub fn analyze(
    robot: &Robot,
    trajectory: &Trajectory,
    spans: &[Span],
    options: &MetricsOptions,
) -> Analysis {
    let frames = frame_metrics(robot, trajectory, &options.rula);
    let whole =
        Span { label: "whole".to_owned(), start: trajectory.start(), end: trajectory.end() };
    let whole = span_metrics(&frames, &whole, options);
    let segments = spans.iter().map(|s| span_metrics(&frames, s, options)).collect();
    Analysis { frames, whole, segments }
}
