//! A whole task: decompose, solve every segment from where the last one really ended, join
//! segments (+Tr within an action, +Se between actions) and report on each.
//!
//! The joint limits (position, velocity, acceleration) are an invariant of the output: a
//! segment that exceeds a rate limit on its own is slowed down as a whole (it starts and ends
//! at rest, so its neighbours do not change); a +Tr blend that exceeds one is shortened, down
//! to switching at rest; and the output at its rate is checked again at every instant of its
//! Hermite curve, slowing the segments it still finds too fast. What cannot be repaired (a
//! position limit) is a warning naming the segment, whose report is then not ok.

use std::sync::Mutex;
use std::sync::mpsc::{Sender, channel};
use std::time::Instant;

use super::assembly::{Assembly, Checkpointed};
use super::chart::Chart;
use super::checks::{self, CheckError};
use super::constrained_rrt::constrained_rrt_monitored;
use super::control::{BaselineOptions, ControlError, ControlOptions, ControlRun};
use super::hamp::{HampOptions, HandoverTarget, plan_handover};
use super::judge::{self, Judgement};
use super::map::{MapError, MapOptions, MapSummary, map_segment};
use super::monitor::{Monitor, deadline_after};
use super::problem::{Component, SegmentProblem};
use super::qp::{self, QpError, QpOptions};
use super::references::{Placed, reference_ends, reference_samples};
use super::report::{
    Fallback, Plan, QpStats, SegmentReport, SegmentSwivelMap, Tolerance, VariableError, Warning,
    WarningKind,
};
use super::rrt::{RrtError, RrtOptions, RrtStats, rrt_connect_monitored};
use super::timing::{TimedPath, time_constrained, time_parameterise};
use super::{clik, gpm, pmp};
use crate::collision::CollisionScene;
use crate::decompose::{
    ArmState, DecomposeError, DecomposeOptions, PlannedAction, PlannedSegment, SegmentPattern,
    decompose, goal_error,
};
use crate::kinematics::{HatState, arm_pose, hat_to_cpsa, ik_cpsa};
use crate::language::{self, ActionBody, PrimitiveConstraint, SolverChoice, Space, Task, Variable};
use crate::math::{DOF, JointVector, Real, Vector3};
use crate::metrics::smoothness::{normalised_jerk, speed_peaks};
use crate::parallel;
use crate::profile::{BodyFrames, ProfileError, Reference, Role, Sample};
use crate::robot::Robot;
use crate::trajectory::{self, Limits, Trajectory, TrajectoryError, capsule_distances, peaks};

/// Settings of [`plan`].
///
/// The settings every solver shares are fields of their own ([`PlanOptions::tolerance`],
/// [`PlanOptions::safety_distance`]); `plan` gives them to each solver, replacing the
/// solver's own copy (`qp.tolerance`, `qp.safety_distance`, `rrt.clearance`, ...), which
/// only a solver called on its own uses.
#[derive(Debug, Clone)]
pub struct PlanOptions {
    /// When a goal counts as reached and a path as kept, for every solver; default 1 mm, 1°.
    pub tolerance: Tolerance,
    /// d_s, the distance every solver keeps from obstacles and between non-adjacent links
    /// (m), default 0.01: the QP's damper rows, the RRTs' clearance, the swivel map's free
    /// cells, and the start checks.
    pub safety_distance: Real,
    /// The decomposition (Opt1/Opt2, action planner, default durations; Opt1 and Opt2's
    /// clearance and goal tolerance come from the plan's).
    pub decompose: DecomposeOptions,
    /// The velocity QP (its tolerance and safety distance come from the plan's).
    pub qp: QpOptions,
    /// RRT-Connect (its seed comes from the task, its clearance is the safety distance).
    pub rrt: RrtOptions,
    /// The swivel map (its safety distance is the plan's).
    pub map: MapOptions,
    /// The baselines GPM, CLIK and PMP and their control loop (its tolerance is the plan's).
    pub baselines: BaselineOptions,
    /// Solver for every segment, overriding the task and its actions.
    pub solver: Option<SolverChoice>,
    /// Output rate (Hz), overriding the task's `settings { rate }`.
    pub rate: Option<Real>,
    /// The acceleration limits as a multiple of the robot's, overriding the task's
    /// `settings { acceleration }`.
    pub acceleration_scale: Option<Real>,
    /// Wall-clock limit of the whole plan (s), default none. Checked inside every solver loop;
    /// when it passes the plan fails with a `timeout`. Without it the outcome never depends
    /// on the machine's speed.
    pub time_limit: Option<Real>,
    /// How large a motion may be planned (samples, segments).
    pub limits: language::Limits,
    /// A start (of the task or an action) closer to an obstacle than the safety distance is
    /// a warning rather than an error.
    pub allow_close_start: bool,
}

impl Default for PlanOptions {
    fn default() -> Self {
        let qp = QpOptions::default();
        Self {
            tolerance: qp.tolerance,
            safety_distance: qp.safety_distance,
            decompose: DecomposeOptions::default(),
            qp,
            rrt: RrtOptions::default(),
            map: MapOptions::default(),
            baselines: BaselineOptions::default(),
            solver: None,
            rate: None,
            acceleration_scale: None,
            time_limit: None,
            limits: language::Limits::default(),
            allow_close_start: false,
        }
    }
}

/// How far planning has got, for progress displays: `done` whole segments, then `fraction`
/// of the next, so (done + fraction) / total grows from 0 to 1. Reported when a segment
/// starts and ends and from inside the solvers' loops (the QP's share of its reference time,
/// an RRT's share of its sample budget).
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    /// Segments solved so far.
    pub done: usize,
    /// Segments in the task.
    pub total: usize,
    /// The action being solved (or the last one solved, once `done == total`).
    pub action: String,
    /// The segment being solved within its action (0-based).
    pub segment: usize,
    /// The share of that segment done, in [0, 1].
    pub fraction: Real,
}

impl Progress {
    /// The share of the whole plan done, in [0, 1].
    pub fn overall(&self) -> Real {
        if self.total == 0 { 1.0 } else { (self.done as Real + self.fraction) / self.total as Real }
    }
}

/// Why a task cannot be planned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// The decomposition failed.
    #[error(transparent)]
    Decompose(#[from] DecomposeError),
    /// The task has obstacles but parts of the arm carry no capsule.
    #[error(
        "the task has obstacles but the robot has no collision geometry on some of its parts, \
         so they cannot be checked: {}",
        warnings.join("; ")
    )]
    NoArmGeometry {
        /// The robot's geometry warnings.
        warnings: Vec<String>,
    },
    /// The output rate is not positive and finite.
    #[error("invalid output rate {rate} Hz: it must be positive and finite")]
    InvalidRate {
        /// The rate asked for (Hz).
        rate: Real,
    },
    /// The acceleration scale is not positive and finite.
    #[error("invalid acceleration scale {scale}: it must be positive and finite")]
    InvalidAccelerationScale {
        /// The scale asked for.
        scale: Real,
    },
    /// The solver asked for does not exist yet for this kind of segment.
    #[error(
        "action `{action}`: solver `{}` is not available yet for pattern-{} segments; use \
         `auto`, `qp`, `rrt`, `map`, `gpm`, `clik` or `pmp`",
        solver.name(),
        pattern.number()
    )]
    UnsupportedSolver {
        /// The action.
        action: String,
        /// The solver asked for.
        solver: SolverChoice,
        /// The segment's pattern.
        pattern: SegmentPattern,
    },
    /// The RRT found no path (asked for explicitly; `auto` falls back to the QP).
    #[error("action `{action}`, segment {}: rrt: {source}", segment + 1)]
    Rrt {
        /// The action.
        action: String,
        /// Segment index (0-based).
        segment: usize,
        /// Why.
        source: RrtError,
    },
    /// The swivel map found no profile (asked for explicitly).
    #[error("action `{action}`, segment {}: map: {source}", segment + 1)]
    Map {
        /// The action.
        action: String,
        /// Segment index (0-based).
        segment: usize,
        /// Why.
        source: MapError,
    },
    /// A segment's references cannot be built.
    #[error("action `{action}`, segment {}: {source}", segment + 1)]
    Reference {
        /// The action.
        action: String,
        /// Segment index (0-based).
        segment: usize,
        /// Why.
        source: ProfileError,
    },
    /// The QP failed on a segment.
    #[error("action `{action}`, segment {}: {source}", segment + 1)]
    Qp {
        /// The action.
        action: String,
        /// Segment index (0-based).
        segment: usize,
        /// Why.
        source: QpError,
    },
    /// A baseline (gpm, clik, pmp) failed on a segment.
    #[error("action `{action}`, segment {}: {}: {source}", segment + 1, solver.name())]
    Baseline {
        /// The action.
        action: String,
        /// Segment index (0-based).
        segment: usize,
        /// The baseline.
        solver: SolverChoice,
        /// Why.
        source: ControlError,
    },
    /// The decomposed task is too large, or an action starts too close to an obstacle.
    #[error(transparent)]
    Check(#[from] CheckError),
    /// The HAMP planner failed on a segment.
    #[error("action `{action}`, segment {}: hamp: {source}", segment + 1)]
    Hamp {
        /// The action.
        action: String,
        /// Segment index (0-based).
        segment: usize,
        /// Why.
        source: super::hamp::HampError,
    },
    /// Joining or resampling the segments failed.
    #[error("joining the segments: {0}")]
    Trajectory(#[from] TrajectoryError),
}

/// Plans `task` on `robot`: the joint trajectory at the output rate and one report per
/// segment. A goal missed beyond tolerance is not an error: the segment's report says so and
/// [`Plan::warnings`] names it.
///
/// # Errors
/// [`SolveError`]: the task does not decompose, a solver is unavailable, or a segment's QP
/// fails (naming the action, segment and time).
pub fn plan(robot: &Robot, task: &Task, options: &PlanOptions) -> Result<Plan, SolveError> {
    plan_with_progress(robot, task, options, &mut |_| {})
}

/// [`plan`], calling `progress` when each segment starts and ends and from inside the
/// solvers' loops (see [`Progress`]).
///
/// # Errors
/// As [`plan`].
pub fn plan_with_progress(
    robot: &Robot,
    task: &Task,
    options: &PlanOptions,
    progress: &mut dyn FnMut(&Progress),
) -> Result<Plan, SolveError> {
    let rate = options.rate.unwrap_or(task.settings.rate);
    if !(rate.is_finite() && rate > 0.0) {
        return Err(SolveError::InvalidRate { rate });
    }
    if !task.scene.is_empty() && !robot.has_arm_geometry() {
        return Err(SolveError::NoArmGeometry { warnings: robot.geometry_warnings.clone() });
    }
    let scale = options.acceleration_scale.unwrap_or(task.settings.acceleration);
    if !(scale.is_finite() && scale > 0.0) {
        return Err(SolveError::InvalidAccelerationScale { scale });
    }
    let deadline = options.time_limit.and_then(deadline_after);
    // The ends Opt1 and Opt2 choose keep the plan's safety distance, with room for its
    // tolerance.
    let mut decompose_options = options.decompose.clone();
    decompose_options.opt.clearance = options.safety_distance;
    decompose_options.opt.goal_tolerance = (options.tolerance.position, options.tolerance.angle);
    let decomposition = decompose(robot, task, &decompose_options)?;
    let task_b = task.in_base_frame(&robot.structure.shoulder_in_base_link);
    let bounds = checks::Bounds {
        rate,
        control_rate: 1.0 / options.qp.step,
        safety: options.safety_distance,
        limits: &options.limits,
        allow_close_start: options.allow_close_start,
    };
    let close_starts = checks::before_solving(robot, &task_b, &decomposition, &bounds)?;
    let total = decomposition.actions.iter().map(|a| a.segments.len()).sum();
    // Each action's obstacles (its `contact` ones left out), kept for the reports written
    // while later segments are solved.
    let scenes: Vec<CollisionScene> = (decomposition.actions.iter())
        .map(|a| CollisionScene::new(&task_b.action_scene(a.index)))
        .collect();
    let mut state = Solver {
        robot,
        task: &task_b,
        options,
        qp: QpOptions {
            acceleration_scale: scale,
            tolerance: options.tolerance,
            safety_distance: options.safety_distance,
            ..options.qp
        },
        limits: Limits::of(robot).with_acceleration_scale(scale),
        deadline,
        rate,
        q: decomposition.start,
        pieces: Vec::with_capacity(total),
        notes: Vec::new(),
    };
    // Solving is sequential (each segment starts where the last ended); judging and
    // reporting a solved segment is not: a thread of its own reports the segments as they are
    // solved, and once the last is solved this thread joins them into the output and then
    // reports beside it. (A thread, not the pool: it waits for the segments, and a pool's
    // worker must not wait.) Each report lands in its segment's slot, whichever thread wrote
    // it.
    let reporter = state.reporter();
    let (sender, receiver) = channel::<(usize, Job, Solved)>();
    let queue = Mutex::new(receiver);
    let slots: Mutex<Vec<Option<Reported>>> = Mutex::new((0..total).map(|_| None).collect());
    let report_all = || {
        loop {
            // The lock is held while waiting, not while reporting.
            let next = queue.lock().unwrap_or_else(|e| e.into_inner()).recv();
            let Ok((slot, job, solution)) = next else { break };
            let reported = reporter.report(job, solution);
            slots.lock().unwrap_or_else(|e| e.into_inner())[slot] = Some(reported);
        }
    };
    let joined = std::thread::scope(|scope| {
        let writer = scope.spawn(report_all);
        let solved = (decomposition.actions.iter().zip(&scenes))
            .try_for_each(|(action, scene)| state.action(action, scene, total, progress, &sender));
        // The queue closes once every segment sent is taken, whether or not all were solved.
        drop(sender);
        let joined = solved.and_then(|()| {
            if state.pieces.is_empty() {
                // No action: the arm stays at the start.
                let still = vec![JointVector::zeros()];
                Ok((Trajectory::new(vec![0.0], vec![decomposition.start], still)?, Vec::new()))
            } else {
                state.join_keeping_limits()
            }
        });
        report_all();
        writer.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        joined
    });
    let (whole, mut notes) = joined?;
    let mut reported: Vec<Reported> =
        slots.into_inner().unwrap_or_else(|e| e.into_inner()).into_iter().flatten().collect();
    state.complete(&mut reported, &whole);
    let mut warnings = close_starts;
    warnings.extend(state.notes);
    warnings.append(&mut notes);
    if !task.scene.is_empty() {
        warnings.extend(robot.geometry_warnings.iter().map(|w| {
            Warning::on_task(WarningKind::CollisionGeometry, format!("collision geometry: {w}"))
        }));
    }
    let placed: Vec<Placed> = state
        .pieces
        .iter()
        .map(|p| Placed { start: p.start, stretch: p.stretch, problem: &p.problem })
        .collect();
    // Each segment's start and action, for the obstacles an action touches on purpose.
    let spans: Vec<(Real, usize)> = state.pieces.iter().map(|p| (p.start, p.action)).collect();
    // The references and the output's distances, side by side on the thread pool.
    let ((references, reference_ends), distances) = parallel::join(
        || (reference_samples(robot, &placed, whole.times()), reference_ends(robot, &placed)),
        || {
            capsule_distances(&whole, robot, &task_b.scene, |sample, obstacle| {
                let t = whole.times()[sample];
                spans.iter().rev().find(|(start, _)| *start <= t).is_some_and(|(_, action)| {
                    task.actions[*action].contact.iter().any(|c| c == obstacle)
                })
            })
        },
    );
    let mut segments = Vec::with_capacity(state.pieces.len());
    let mut wrist_reference = Vec::new();
    let mut swivel_maps = Vec::new();
    for (piece, reported) in state.pieces.into_iter().zip(reported) {
        wrist_reference.extend(reported.reference.iter().map(|(t, p)| (piece.start + t, *p)));
        if let Some(map) = piece.swivel_map {
            swivel_maps.push(SegmentSwivelMap { segment: segments.len(), map });
        }
        segments.push(reported.report);
    }
    let safety = options.safety_distance;
    warnings.extend(segments.iter().filter_map(|s| checks::too_close(s, safety)));
    warnings.extend(segments.iter().filter(|s| !s.reached).map(missed));
    warnings.extend(segments.iter().filter(|s| !s.path_kept).map(left_path));
    warnings
        .extend(segments.iter().filter(|s| !s.limits_kept).map(|s| over_limits(s, robot, &whole)));
    Ok(Plan {
        task: decomposition.task,
        joint_names: robot.joint_names().iter().map(|n| (*n).to_owned()).collect(),
        rate,
        trajectory: whole,
        segments,
        wrist_reference,
        safety_distance: options.safety_distance,
        warnings,
        references,
        reference_ends,
        distances,
        swivel_maps,
    })
}

/// Rounds of slowing the segments that the output at its rate still finds too fast.
const OUTPUT_ROUNDS: usize = 8;
/// Relative tolerance of the limit checks: rounding, not motion.
const LIMIT_TOLERANCE: Real = 1e-9;

/// One solved segment waiting to be joined: its motion from time 0 (at the solver's rate) and
/// what joining decides.
struct Piece {
    /// The action's index in the task.
    action: usize,
    /// The action's name and the segment's index in it.
    name: String,
    segment: usize,
    trajectory: Trajectory,
    /// The segment's references, for [`Plan::references`].
    problem: SegmentProblem,
    /// The factor the segment is slowed down by (1: as solved).
    stretch: Real,
    /// Start in the plan's time (s), once joined.
    start: Real,
    /// The map and profile, when the swivel map solved the segment.
    swivel_map: Option<MapSummary>,
}

/// How much slower a solved segment must run to keep the rate `limits` on its own (1 when
/// it keeps them): joining starts from this, so that the limit rounds only repair what
/// joining changed.
fn own_stretch(trajectory: &Trajectory, limits: &Limits) -> Real {
    let stretch = peaks(trajectory, trajectory.start(), trajectory.end()).stretch(limits);
    if stretch > 1.0 + LIMIT_TOLERANCE { stretch * (1.0 + 1e-6) } else { 1.0 }
}

impl Piece {
    fn timed(&self) -> Trajectory {
        if self.stretch > 1.0 {
            self.trajectory.stretched(self.stretch)
        } else {
            self.trajectory.clone()
        }
    }
}

/// A solved segment's report, in its own time until [`Solver::complete`], and its reference
/// wrist path at the output rate.
struct Reported {
    report: SegmentReport,
    reference: Vec<(Real, Vector3)>,
}

/// The planning state between actions.
struct Solver<'a> {
    robot: &'a Robot,
    task: &'a Task,
    options: &'a PlanOptions,
    /// The QP's options with the plan's acceleration scale, tolerance and safety distance.
    qp: QpOptions,
    /// The limits every output holds.
    limits: Limits,
    /// When the user's time limit passes, if there is one.
    deadline: Option<Instant>,
    rate: Real,
    /// Where the arm really is: the end of what has been solved.
    q: JointVector,
    /// The segments solved, in order.
    pieces: Vec<Piece>,
    /// Warnings other than missed goals: fallbacks and stretched durations.
    notes: Vec<Warning>,
}

/// One segment to solve, with what every solver and the report need.
struct Job<'a> {
    action: &'a PlannedAction,
    /// The segment's index in its action.
    k: usize,
    segment: &'a PlannedSegment,
    problem: SegmentProblem,
    /// The action's obstacles (its `contact` ones left out).
    scene: &'a CollisionScene,
    chart: Chart,
    /// Whether the segment's path is the action's hard path.
    hard: bool,
}

impl Job<'_> {
    /// The warning prefix naming the action and segment.
    fn name(&self) -> String {
        format!("action `{}`, segment {}", self.action.name, self.k + 1)
    }

    /// A warning of `kind` naming the job's action and segment.
    fn warning(&self, kind: WarningKind, message: String) -> Warning {
        Warning::on_segment(kind, &self.action.name, self.k, message)
    }

    fn rrt_failed(&self, source: RrtError) -> SolveError {
        SolveError::Rrt { action: self.action.name.clone(), segment: self.k, source }
    }
}

impl<'a> Solver<'a> {
    /// Solves the action's segments one after the other, each from where the last ended,
    /// reporting progress, and sends each to `reports` as it is solved.
    fn action<'s>(
        &mut self,
        action: &'s PlannedAction,
        scene: &'s CollisionScene,
        total: usize,
        progress: &mut dyn FnMut(&Progress),
        reports: &Sender<(usize, Job<'s>, Solved)>,
    ) -> Result<(), SolveError> {
        let hard = matches!(
            &self.task.actions[action.index].body,
            ActionBody::Constraints { path: Some(path), .. } if path.hard
        );
        for (k, segment) in action.segments.iter().enumerate() {
            let problem = segment_problem(self.robot, &self.q, action, k, segment)?;
            let chart = Chart::new(self.robot, &problem);
            // A hard path gives the segments that carry it their path primitives; the
            // decomposition's holds are kept as exactly by every solver, hard or not.
            let carries_path = segment
                .primitives
                .iter()
                .any(|p| matches!(p.constraint, PrimitiveConstraint::Path(_)));
            let job = Job { action, k, segment, problem, scene, chart, hard: hard && carries_path };
            let done = self.pieces.len();
            let name = action.name.clone();
            // Never backwards, when `auto` goes on from one solver to another.
            let mut most: Real = 0.0;
            let mut report = |fraction: Real| {
                most = most.max(fraction);
                let fraction = most;
                progress(&Progress { done, total, action: name.clone(), segment: k, fraction })
            };
            report(0.0);
            let mut solution = self.solve(&job, &mut Monitor::new(self.deadline, &mut report))?;
            if let Some(end) = solution.trajectory.positions().last() {
                self.q = *end;
            }
            self.pieces.push(Piece {
                action: action.index,
                name: action.name.clone(),
                segment: k,
                trajectory: solution.trajectory.clone(),
                problem: job.problem.clone(),
                stretch: 1.0,
                start: 0.0,
                swivel_map: solution.swivel_map.take(),
            });
            // The writer is gone only when it panicked, which its join passes on.
            let _ = reports.send((done, job, solution));
            let done = self.pieces.len();
            progress(&Progress {
                done,
                total,
                action: action.name.clone(),
                segment: k,
                fraction: 0.0,
            });
        }
        Ok(())
    }

    /// Joins the solved segments into the output at its rate, keeping the limits: each
    /// segment slowed as a whole where it exceeds a rate limit, each +Tr blend shortened where
    /// it does, and the output checked again at every instant until it holds the limits (or
    /// the rounds run out). Returns the output and the notes on what was repaired.
    fn join_keeping_limits(&mut self) -> Result<(Trajectory, Vec<Warning>), SolveError> {
        parallel::map_mut(&mut self.pieces, |_, piece| {
            piece.stretch = own_stretch(&piece.trajectory, &self.limits);
        });
        // The index of each action's first piece: a round rejoins from the first action it
        // slowed a piece of.
        let action_starts: Vec<usize> = (0..self.pieces.len())
            .filter(|&i| i == 0 || self.pieces[i].action != self.pieces[i - 1].action)
            .collect();
        let mut joined = Checkpointed::default();
        let mut from = 0;
        let mut round = 0;
        let (output, blend_notes) = loop {
            let (whole, notes) = self.join_from(&mut joined, &action_starts, from)?;
            let output = whole.resample(self.rate)?;
            round += 1;
            let slowed = parallel::map_mut(&mut self.pieces, |_, piece| {
                let end = piece.start + piece.trajectory.duration() * piece.stretch;
                let stretch = peaks(&output, piece.start, end).stretch(&self.limits);
                let slowed = stretch > 1.0 + LIMIT_TOLERANCE && round < OUTPUT_ROUNDS;
                if slowed {
                    // A little more than asked: the output's samples fall elsewhere on the
                    // slower motion, and its curve between them with them.
                    piece.stretch *= stretch * 1.02;
                }
                slowed
            });
            match slowed.iter().position(|&slowed| slowed) {
                Some(first) => from = action_starts.partition_point(|&start| start <= first) - 1,
                None => break (output, notes),
            }
        };
        let mut notes = blend_notes;
        for piece in &self.pieces {
            if piece.stretch > 1.0 {
                let solved = piece.trajectory.duration();
                let message = format!(
                    "action `{}`, segment {}: slowed down {:.3} times ({:.2} s instead of {:.2} s) \
                     to keep every joint within its velocity and acceleration limits",
                    piece.name,
                    piece.segment + 1,
                    piece.stretch,
                    solved * piece.stretch,
                    solved
                );
                notes.push(Warning::on_segment(
                    WarningKind::SlowedDown,
                    &piece.name,
                    piece.segment,
                    message,
                ));
            }
        }
        Ok((output, notes))
    }

    /// Completes each segment's report (in the pieces' order) with where joining put it and
    /// the measures of the `output`.
    fn complete(&self, reported: &mut [Reported], output: &Trajectory) {
        parallel::map_mut(reported, |i, reported| {
            complete(&self.pieces[i], &mut reported.report, output, self.robot, &self.limits)
        });
    }

    /// Every segment joined at its current stretch: +Tr within an action (each blend
    /// shortened where it would exceed a limit), +Se between actions; `joined` is kept as
    /// joined up to action `from` (of those starting at the pieces `action_starts`) and
    /// joined again from there. Sets the start of each piece joined; returns the trajectory
    /// and a note per shortened blend.
    fn join_from(
        &mut self,
        joined: &mut Checkpointed<Warning>,
        action_starts: &[usize],
        from: usize,
    ) -> Result<(Trajectory, Vec<Warning>), SolveError> {
        // Each join only changes the samples from its seam on, so only the tail is rebuilt:
        // joining stays linear in the number of segments.
        for (k, &first) in action_starts.iter().enumerate().skip(from) {
            let whole = joined.rewind(k);
            let mut notes = Vec::new();
            let end = action_starts.get(k + 1).copied().unwrap_or(self.pieces.len());
            let action_start = whole.end().unwrap_or(0.0);
            let mut action_joined = Assembly::default();
            let mut last: Option<(Real, Real)> = None; // (start, duration) of the previous segment
            for i in first..end {
                let segment = self.pieces[i].timed();
                let duration = segment.duration();
                let start = match last {
                    Some((prev_start, prev_duration)) => {
                        let overlap = self.task.settings.transition * prev_duration.min(duration);
                        let used = action_joined
                            .join_with(&segment, overlap, |before, next| {
                                self.blend(before, next, overlap)
                            })?
                            .unwrap_or(0.0);
                        if used < overlap {
                            let piece = &self.pieces[i];
                            let message = format!(
                                "action `{}`, segment {}: the +Tr blend into it overlaps {:.3} s \
                                 instead of {:.3} s to keep the joint limits",
                                piece.name,
                                piece.segment + 1,
                                used,
                                overlap
                            );
                            notes.push(Warning::on_segment(
                                WarningKind::BlendShortened,
                                &piece.name,
                                piece.segment,
                                message,
                            ));
                        }
                        prev_start + prev_duration - used
                    }
                    None => {
                        action_joined.join_sequential(&shifted(&segment, action_start)?)?;
                        action_start
                    }
                };
                last = Some((start, duration));
                self.pieces[i].start = start;
            }
            if let Some(action_trajectory) = action_joined.finish()? {
                whole.join_sequential(&action_trajectory)?;
            }
            joined.close_group(notes);
        }
        let (trajectory, notes) = joined.assembled()?;
        Ok((trajectory.ok_or(TrajectoryError::Empty)?, notes))
    }

    /// The +Tr blend of `before` (ending with a segment at rest) into `next` (starting at rest
    /// where it ends) over `overlap` (appendix A) when it keeps the limits over the overlap;
    /// else over half, a quarter of it, and at last none (a switch at rest, which keeps them
    /// whenever both sides do). Returns the joined trajectory and the overlap used.
    fn blend(
        &self,
        before: &Trajectory,
        next: &Trajectory,
        overlap: Real,
    ) -> Result<(Trajectory, Real), SolveError> {
        for used in [overlap, 0.5 * overlap, 0.25 * overlap] {
            if used <= 0.0 {
                break;
            }
            let joined = trajectory::join_transitional(before, next, used)?;
            let window = peaks(&joined, before.end() - used, before.end());
            if window.stretch(&self.limits) <= 1.0 + LIMIT_TOLERANCE
                && window.positions_within(&self.limits, LIMIT_TOLERANCE)
            {
                return Ok((joined, used));
            }
        }
        Ok((trajectory::join_transitional(before, next, 0.0)?, 0.0))
    }

    /// Solves one segment with its solver: the override, else its own choice. `rrt` plans a
    /// goal segment (pattern 2) in joint space and a segment with a path (patterns 1 and 3) in
    /// its constrained space. `auto` (docs/design.md §5) gives a goal segment among obstacles to
    /// the RRT, falling back to the QP with a warning when the RRT finds no path; it gives a
    /// mixed segment (pattern 3) to the QP and, when the QP stalls, misses the goal or leaves
    /// a hard path, to the constrained RRT, keeping the QP's closest result with a warning
    /// when that fails too; and every other segment to the QP.
    fn solve(&mut self, job: &Job, monitor: &mut Monitor) -> Result<Solved, SolveError> {
        let pattern = job.segment.pattern;
        let kept = |this: &mut Self, source: RrtError, why: &str| {
            let name = job.name();
            let message = format!("{name}: {why}; rrt: {source}; the QP's result is kept");
            this.notes.push(job.warning(WarningKind::RrtFailed, message));
        };
        match self.options.solver.unwrap_or(job.segment.solver) {
            SolverChoice::Qp => self.qp(job, monitor),
            SolverChoice::Auto if pattern == SegmentPattern::Goal && !job.scene.is_empty() => {
                match self.rrt(job, monitor) {
                    Ok(solved) => Ok(solved),
                    Err(SolveError::Rrt { source, .. }) => {
                        kept(self, source, "a goal segment among obstacles");
                        self.qp(job, monitor)
                    }
                    Err(e) => Err(e),
                }
            }
            SolverChoice::Auto if pattern == SegmentPattern::Mixed => {
                let mut qp = self.qp(job, monitor)?;
                let path_kept = qp.judge_path(self.robot, job, &self.options.tolerance).kept;
                let why = match (qp.reached, path_kept, qp.stalled) {
                    (true, true, _) => return Ok(qp),
                    (_, false, _) => Fallback::QpLeftPath,
                    (_, _, true) => Fallback::QpStalled,
                    _ => Fallback::QpMissedGoal,
                };
                if map_fits(job) {
                    match self.map(job) {
                        Ok(map) if map.reached && map.path_kept() => {
                            return Ok(Solved { fallback: Some(why), ..map });
                        }
                        Ok(_) | Err(SolveError::Map { .. }) => {}
                        Err(e) => return Err(e),
                    }
                }
                match self.constrained(job, monitor) {
                    Ok(rrt) if rrt.reached && rrt.path_kept() => {
                        Ok(Solved { fallback: Some(why), ..rrt })
                    }
                    Ok(_) => {
                        let message = format!(
                            "{}: {}; rrt did not do better; the QP's result is kept",
                            job.name(),
                            why.describe()
                        );
                        self.notes.push(job.warning(WarningKind::RrtNoBetter, message));
                        Ok(qp)
                    }
                    Err(SolveError::Rrt { source, .. }) => {
                        kept(self, source, why.describe());
                        Ok(qp)
                    }
                    Err(e) => Err(e),
                }
            }
            SolverChoice::Auto => self.qp(job, monitor),
            SolverChoice::Rrt if pattern == SegmentPattern::Goal => self.rrt(job, monitor),
            SolverChoice::Rrt => self.constrained(job, monitor),
            SolverChoice::Map => self.map(job),
            SolverChoice::Hamp if pattern == SegmentPattern::Goal => self.hamp(job),
            SolverChoice::Gpm => self.baseline(job, SolverChoice::Gpm, |r, p, q, o, c| {
                gpm::solve_segment(r, p, q, &o.gpm, c)
            }),
            SolverChoice::Clik => self.baseline(job, SolverChoice::Clik, |r, p, q, o, c| {
                clik::solve_segment(r, p, q, &o.clik, c)
            }),
            SolverChoice::Pmp => self.baseline(job, SolverChoice::Pmp, |r, p, q, o, c| {
                pmp::solve_segment(r, p, q, &o.pmp, c)
            }),
            solver => Err(SolveError::UnsupportedSolver {
                action: job.action.name.clone(),
                solver,
                pattern,
            }),
        }
    }

    fn qp(&self, job: &Job, monitor: &mut Monitor) -> Result<Solved, SolveError> {
        let options = QpOptions { hard_path: job.hard, ..self.qp };
        let solution = qp::solve_segment_monitored(
            self.robot,
            job.scene,
            &job.problem,
            &self.q,
            &options,
            monitor,
        )
        .map_err(|source| SolveError::Qp {
            action: job.action.name.clone(),
            segment: job.k,
            source,
        })?;
        // The path is judged when `auto` decides by it, else by the report.
        Ok(Solved {
            solver: SolverChoice::Qp,
            trajectory: solution.trajectory,
            errors: solution.errors,
            path: None,
            settle: solution.settle,
            reached: solution.reached,
            stalled: solution.stalled,
            qp: solution.stats,
            rrt: None,
            fallback: None,
            swivel_map: None,
        })
    }

    /// A goal segment by RRT-Connect in joint space towards the IK branches of its end state
    /// (the decomposition's configuration first), timed with the bell profile.
    fn rrt(&mut self, job: &Job, monitor: &mut Monitor) -> Result<Solved, SolveError> {
        let end = job.segment.end;
        let mut goals = vec![end];
        if let Ok(state) = ArmState::at(self.robot, &end) {
            if let Ok(branches) = ik_cpsa(self.robot, &state.cpsa, Some(&end)) {
                goals.extend(branches.into_iter().filter(|q| (q - end).amax() > 1e-9));
            }
        }
        let options = self.rrt_options();
        let path = rrt_connect_monitored(self.robot, job.scene, &self.q, &goals, &options, monitor)
            .map_err(|e| job.rrt_failed(e))?;
        let rate = 1.0 / self.options.qp.step;
        let timed = time_parameterise(&self.limits, &path.waypoints, job.segment.duration, rate)?;
        Ok(self.timed(job, timed, path.stats))
    }

    /// A segment with a path by RRT-Connect in its constrained space, timed with the bell
    /// profile along the chart path.
    fn constrained(&mut self, job: &Job, monitor: &mut Monitor) -> Result<Solved, SolveError> {
        let options = self.rrt_options();
        let path = constrained_rrt_monitored(
            self.robot, job.scene, &job.chart, &self.q, &options, monitor,
        )
        .map_err(|e| job.rrt_failed(e))?;
        let rate = 1.0 / self.options.qp.step;
        let (chart, duration) = (&job.chart, job.segment.duration);
        let timed = time_constrained(self.robot, &self.limits, chart, &path, duration, rate)
            .map_err(|e| job.rrt_failed(e))?;
        Ok(self.timed(job, timed, path.stats))
    }

    /// A CPSA segment by the swivel map: Pw and Ow follow their references exactly, θsw the
    /// smoothest free profile (to its goal, if it has one), joints by analytic IK.
    fn map(&mut self, job: &Job) -> Result<Solved, SolveError> {
        let obstacles = self.task.action_scene(job.action.index);
        let options = MapOptions {
            safety_distance: self.options.safety_distance,
            ..self.options.map.clone()
        };
        let (map, profile) = map_segment(self.robot, &obstacles, &job.problem, &self.q, &options)
            .map_err(|source| SolveError::Map {
            action: job.action.name.clone(),
            segment: job.k,
            source,
        })?;
        let summary = MapSummary::new(&map, Some(&profile));
        let solved = self.judged(job, SolverChoice::Map, profile.trajectory, 0.0, false, None);
        Ok(Solved { swivel_map: Some(summary), ..solved })
    }

    /// A segment by one of the baselines, judged like every other solver: the segment's own
    /// goal errors, path and limits, whatever the baseline itself tracked.
    fn baseline(
        &self,
        job: &Job,
        solver: SolverChoice,
        solve: impl Fn(
            &Robot,
            &SegmentProblem,
            &JointVector,
            &BaselineOptions,
            &ControlOptions,
        ) -> Result<ControlRun, ControlError>,
    ) -> Result<Solved, SolveError> {
        let o = &self.options.baselines;
        let control = ControlOptions { tolerance: self.options.tolerance, ..o.control };
        let run = solve(self.robot, &job.problem, &self.q, o, &control).map_err(|source| {
            SolveError::Baseline { action: job.action.name.clone(), segment: job.k, solver, source }
        })?;
        Ok(self.judged(job, solver, run.trajectory, run.settle, run.stalled, None))
    }

    /// A goal segment by the HAMP handover planner towards its end state: the pick-up
    /// patterns, timed by Fitts' law (METHODS.md §3.4).
    fn hamp(&mut self, job: &Job) -> Result<Solved, SolveError> {
        let failed =
            |source| SolveError::Hamp { action: job.action.name.clone(), segment: job.k, source };
        let goal = ArmState::at(self.robot, &job.segment.end)
            .map_err(|e| failed(super::hamp::HampError::Target(e)))?;
        let target =
            HandoverTarget { pw: goal.cpsa.pw, ow: goal.cpsa.ow, swivel: Some(goal.cpsa.swivel) };
        let options = HampOptions {
            seed: self.task.settings.seed,
            rate: 1.0 / self.options.qp.step,
            ..HampOptions::default()
        };
        let planned =
            plan_handover(self.robot, &self.q, &target, job.scene, &options).map_err(failed)?;
        if !planned.limit_violations.is_empty() {
            let message = format!("{}: the hamp motion exceeds a joint speed limit", job.name());
            self.notes.push(job.warning(WarningKind::HampOverSpeed, message));
        }
        Ok(self.judged(job, SolverChoice::Hamp, planned.trajectory, 0.0, false, None))
    }

    fn rrt_options(&self) -> RrtOptions {
        RrtOptions {
            seed: self.task.settings.seed,
            clearance: self.options.safety_distance,
            ..self.options.rrt
        }
    }

    /// An RRT path as solved: the stretch noted, the end's errors.
    fn timed(&mut self, job: &Job, timed: TimedPath, stats: RrtStats) -> Solved {
        if timed.stretched {
            let message = format!(
                "{}: the rrt path takes {:.2} s instead of {:.2} s to keep every joint within \
                 its velocity and acceleration limits",
                job.name(),
                timed.duration,
                job.segment.duration
            );
            self.notes.push(job.warning(WarningKind::RrtSlowed, message));
        }
        self.judged(job, SolverChoice::Rrt, timed.trajectory, 0.0, false, Some(stats))
    }

    /// A solver's trajectory judged on the segment's own terms, whichever solver made it
    /// ([`judge::judge`]).
    fn judged(
        &self,
        job: &Job,
        solver: SolverChoice,
        trajectory: Trajectory,
        settle: Real,
        stalled: bool,
        rrt: Option<RrtStats>,
    ) -> Solved {
        let states = judge::sample_states(self.robot, &trajectory);
        let Judgement { errors, reached, path_errors, path_kept } = judge::judge_states(
            self.robot,
            &job.problem,
            &job.chart,
            job.hard,
            &states,
            &self.options.tolerance,
            &self.q,
        );
        Solved {
            solver,
            trajectory,
            errors,
            path: Some(PathJudgement { states, errors: path_errors, kept: path_kept }),
            settle,
            reached,
            stalled,
            qp: QpStats::default(),
            rrt,
            fallback: None,
            swivel_map: None,
        }
    }

    /// What the reports of the segments solved read of the plan.
    fn reporter(&self) -> Reporter<'a> {
        Reporter { robot: self.robot, tolerance: self.options.tolerance, rate: self.rate }
    }
}

/// What a segment's report reads besides the segment: the robot, the tolerance and the
/// output rate, for the thread that writes the reports.
#[derive(Clone, Copy)]
struct Reporter<'a> {
    robot: &'a Robot,
    tolerance: Tolerance,
    rate: Real,
}

impl Reporter<'_> {
    /// The solved segment judged (where that waited for the report) and reported.
    fn report(&self, job: Job, mut solution: Solved) -> Reported {
        let path = (solution.path.take())
            .unwrap_or_else(|| judge_path(self.robot, &job, &self.tolerance, &solution.trajectory));
        let reference = self.reference(&job.problem);
        let report = self.segment_report(&job, &solution, &path);
        Reported { report, reference }
    }

    /// The segment's reference Pw at the output rate, in its own time.
    fn reference(&self, problem: &SegmentProblem) -> Vec<(Real, Vector3)> {
        trajectory::sample_times(0.0, problem.duration, self.rate)
            .into_iter()
            .filter_map(|t| reference_wrist(self.robot, problem, t).map(|p| (t, p)))
            .collect()
    }

    /// The segment's report as solved, in its own time; [`complete`] adds what joining
    /// decides and the measures of the output.
    fn segment_report(&self, job: &Job, solution: &Solved, path: &PathJudgement) -> SegmentReport {
        let tolerance = &self.tolerance;
        let error = |variable: Variable, error: Real| VariableError {
            variable,
            error,
            within: judge::within(tolerance, variable, error),
        };
        let components = job.problem.components.iter();
        let errors = components.clone().zip(solution.errors).map(|(c, e)| error(c.variable, e));
        let path_errors = components
            .zip(path.errors)
            .filter(|(c, _)| c.role == Role::Path)
            .map(|(c, e)| error(c.variable, e))
            .collect();
        let (action, segment) = (job.action, job.segment);
        SegmentReport {
            action: action.name.clone(),
            action_index: action.index,
            segment: job.k,
            action_type: action.classification.as_ref().map(|c| c.action_type),
            space: segment.space,
            pattern: segment.pattern,
            solver: solution.solver,
            focus: segment.primitives.first().map(|p| p.variables.clone()).unwrap_or_default(),
            start: 0.0,
            end: solution.trajectory.duration(),
            duration: segment.duration,
            settle: solution.settle,
            errors: errors.collect(),
            path_errors,
            hard_path: job.hard,
            path_kept: path.kept,
            clearance: trajectory::min_clearance(&solution.trajectory, self.robot, job.scene),
            limit_margin: limit_margin(self.robot, &solution.trajectory),
            stalled: solution.stalled,
            reached: solution.reached,
            qp: solution.qp,
            rrt: solution.rrt,
            fallback: solution.fallback,
            peak_velocity_ratio: 0.0,
            peak_acceleration_ratio: 0.0,
            limits_kept: true,
            slowed_down: 1.0,
            joint_jerk: 0.0,
            wrist_jerk: 0.0,
            speed_peaks: featured_peaks(
                &segment_focus(job),
                solution.trajectory.times(),
                &path.states,
            ),
        }
    }
}

/// A segment's references, starting from the arm at `q`.
pub(crate) fn segment_problem(
    robot: &Robot,
    q: &JointVector,
    action: &PlannedAction,
    k: usize,
    segment: &PlannedSegment,
) -> Result<SegmentProblem, SolveError> {
    let failed = |source| SolveError::Reference { action: action.name.clone(), segment: k, source };
    let state = ArmState::at(robot, q).map_err(|e| SolveError::Qp {
        action: action.name.clone(),
        segment: k,
        source: QpError::Singular { time: 0.0, source: e },
    })?;
    let frames = BodyFrames { shoulder_frame: state.hat.shoulder_frame, ow: state.cpsa.ow };
    let component = |variable: Variable| -> Result<Component, ProfileError> {
        let start = state.value(variable);
        let duration = segment.duration;
        let found = segment
            .primitives
            .iter()
            .find_map(|p| p.variables.iter().position(|v| *v == variable).map(|i| (p, i)));
        let (reference, role) = match found {
            Some((p, i)) => match &p.constraint {
                PrimitiveConstraint::Goal(targets) => {
                    (Reference::goal(variable, start, targets[i], duration)?, Role::Goal)
                }
                PrimitiveConstraint::Path(feature) => {
                    (Reference::path(variable, start, feature, &frames, duration)?, Role::Path)
                }
                PrimitiveConstraint::Hold => {
                    (Reference::hold(variable, start, duration)?, Role::Path)
                }
            },
            // The decomposition covers the whole space; a gap is held.
            None => (Reference::hold(variable, start, duration)?, Role::Path),
        };
        Ok(Component { variable, reference, role })
    };
    let [a, b, c] = segment.space.variables();
    Ok(SegmentProblem {
        space: segment.space,
        components: [
            component(a).map_err(failed)?,
            component(b).map_err(failed)?,
            component(c).map_err(failed)?,
        ],
        duration: segment.duration,
    })
}

/// Whether `auto` may hand the segment to the swivel map (DESIGN.md §5): a CPSA segment that
/// holds or paths the wrist (Pw and Ow) among obstacles, so that only θsw is left to move.
fn map_fits(job: &Job) -> bool {
    job.problem.space == Space::Cpsa
        && !job.scene.is_empty()
        && job
            .problem
            .components
            .iter()
            .all(|c| c.variable == Variable::Swivel || c.role == Role::Path)
}

/// The segment's featured variable: the first of its focus, else the wrist position.
fn segment_focus(job: &Job) -> Variable {
    job.segment
        .primitives
        .first()
        .and_then(|p| p.variables.first().copied())
        .unwrap_or(Variable::Pw)
}

/// The number of peaks of `variable`'s speed over a trajectory's samples (the change of its
/// value between samples, over their interval), from their `times` and `states`.
fn featured_peaks(variable: &Variable, times: &[Real], states: &[Option<ArmState>]) -> usize {
    let speeds: Vec<Real> = (1..states.len())
        .map(|k| match (&states[k - 1], &states[k]) {
            (Some(a), Some(b)) => {
                goal_error(b, &[(*variable, a.value(*variable))]) / (times[k] - times[k - 1])
            }
            _ => 0.0,
        })
        .collect();
    speed_peaks(&speeds)
}

/// Completes a segment's report with where joining put it and the measures of the output
/// over its time: peak rate ratios, whether the limits hold, the normalised jerks.
fn complete(
    piece: &Piece,
    report: &mut SegmentReport,
    output: &Trajectory,
    robot: &Robot,
    limits: &Limits,
) {
    let (start, stretch, solved) = (piece.start, piece.stretch, piece.trajectory.duration());
    report.start = start;
    report.end = start + solved * stretch;
    report.settle *= stretch;
    report.slowed_down = stretch;
    if let Some(c) = report.clearance.as_mut() {
        c.time = start + c.time * stretch;
    }
    let window = peaks(output, report.start, report.end);
    report.peak_velocity_ratio = window.velocity_ratio(limits);
    report.peak_acceleration_ratio = window.acceleration_ratio(limits);
    report.limits_kept = window.stretch(limits) <= 1.0 + LIMIT_TOLERANCE
        && window.positions_within(limits, LIMIT_TOLERANCE);
    let inside: Vec<usize> = (0..output.len())
        .filter(|&k| {
            output.times()[k] >= report.start - 1e-12 && output.times()[k] <= report.end + 1e-12
        })
        .collect();
    let times: Vec<Real> = inside.iter().map(|&k| output.times()[k]).collect();
    let joint_velocities: Vec<JointVector> =
        inside.iter().map(|&k| output.velocities()[k]).collect();
    report.joint_jerk = normalised_jerk(&times, &joint_velocities);
    let wrist: Vec<Vector3> =
        inside.iter().map(|&k| arm_pose(robot, &output.positions()[k]).wrist).collect();
    let wrist_velocities: Vec<Vector3> = (0..wrist.len())
        .map(|k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(wrist.len() - 1));
            if b > a { (wrist[b] - wrist[a]) / (times[b] - times[a]) } else { Vector3::zeros() }
        })
        .collect();
    report.wrist_jerk = normalised_jerk(&times, &wrist_velocities);
}

/// A segment as one of the solvers solved it.
struct Solved {
    solver: SolverChoice,
    /// From time 0.
    trajectory: Trajectory,
    errors: [Real; 3],
    /// How far the motion kept the segment's path: judged at once where `auto` decides by it,
    /// else by the report (`None` until then).
    path: Option<PathJudgement>,
    settle: Real,
    reached: bool,
    stalled: bool,
    qp: QpStats,
    rrt: Option<RrtStats>,
    /// Why `auto` went on from the QP to this solver.
    fallback: Option<Fallback>,
    /// The map and profile, when the swivel map solved it.
    swivel_map: Option<MapSummary>,
}

impl Solved {
    /// The path judgement, measured now if it waited.
    fn judge_path(&mut self, robot: &Robot, job: &Job, tolerance: &Tolerance) -> &PathJudgement {
        self.path.get_or_insert_with(|| judge_path(robot, job, tolerance, &self.trajectory))
    }

    /// Whether the path was kept; false where it has not been judged.
    fn path_kept(&self) -> bool {
        self.path.as_ref().is_some_and(|p| p.kept)
    }
}

/// The states of `trajectory`'s samples and how far it kept `job`'s path.
fn judge_path(
    robot: &Robot,
    job: &Job,
    tolerance: &Tolerance,
    trajectory: &Trajectory,
) -> PathJudgement {
    let states = judge::sample_states(robot, trajectory);
    let (errors, kept) =
        judge::path_errors_of(&job.problem, &job.chart, job.hard, &states, tolerance);
    PathJudgement { states, errors, kept }
}

/// The arm's state at each sample of a solved segment (`None` where singular), which the
/// judgement and the report read, and how far the motion kept the segment's path.
struct PathJudgement {
    states: Vec<Option<ArmState>>,
    /// Largest distance of each component from its path (0 for goals).
    errors: [Real; 3],
    /// The path kept within tolerance, or not hard.
    kept: bool,
}

/// The trajectory with `offset` added to its times.
fn shifted(t: &Trajectory, offset: Real) -> Result<Trajectory, TrajectoryError> {
    Trajectory::new(
        t.times().iter().map(|s| s + offset).collect(),
        t.positions().to_vec(),
        t.velocities().to_vec(),
    )
}

/// Pw asked for at t: the CPSA reference itself, or the HAT reference mapped to CPSA.
fn reference_wrist(robot: &Robot, problem: &SegmentProblem, t: Real) -> Option<Vector3> {
    let [a, b, c] = problem.components.map(|c| c.reference.sample(t));
    match (problem.space, a, b, c) {
        (Space::Cpsa, Sample::Position { value, .. }, _, _) => Some(value),
        (
            Space::Hat,
            Sample::Rotation { value: os, .. },
            Sample::Angle { value: elbow, .. },
            Sample::Rotation { value: ow, .. },
        ) => hat_to_cpsa(robot, &HatState { shoulder_frame: os, elbow_angle: elbow, ow })
            .ok()
            .map(|s| s.pw),
        _ => None,
    }
}

/// The smallest distance of any joint to its position limits over the samples (rad).
fn limit_margin(robot: &Robot, trajectory: &Trajectory) -> Real {
    let (lower, upper) = (robot.lower(), robot.upper());
    trajectory
        .positions()
        .iter()
        .flat_map(|q| (0..DOF).map(move |i| (q[i] - lower[i]).min(upper[i] - q[i])))
        .fold(Real::INFINITY, Real::min)
}

/// The warning for a segment that left its hard path.
fn left_path(s: &SegmentReport) -> Warning {
    let what: Vec<String> = s.path_errors.iter().filter(|e| !e.within).map(describe).collect();
    let message = format!(
        "action `{}`, segment {}: left its hard path: {}",
        s.action,
        s.segment + 1,
        what.join(", ")
    );
    Warning::on_segment(WarningKind::LeftPath, &s.action, s.segment, message)
}

/// "Pw by 3.1 mm", "θsw by 2.00°".
fn describe(e: &VariableError) -> String {
    let measure = e.variable.measure();
    format!("{} by {}", e.variable.symbol(), measure.text(e.error, measure.decimals()))
}

/// The warning for a segment whose output exceeds a joint limit: the speed ratios, and each
/// joint whose position passes a limit in the segment's samples, how far.
fn over_limits(s: &SegmentReport, robot: &Robot, whole: &Trajectory) -> Warning {
    let (lower, upper) = (robot.lower(), robot.upper());
    let mut worst = [(0.0, 0.0, 0.0); DOF];
    for (t, q) in whole.times().iter().zip(whole.positions()) {
        if *t < s.start || *t > s.end {
            continue;
        }
        for i in 0..DOF {
            for (excess, limit) in [(lower[i] - q[i], lower[i]), (q[i] - upper[i], upper[i])] {
                if excess > worst[i].0 {
                    worst[i] = (excess, q[i], limit);
                }
            }
        }
    }
    let passed: Vec<String> = (0..DOF)
        .filter(|&i| worst[i].0 > 0.0)
        .map(|i| {
            let (excess, value, limit) = worst[i];
            format!(
                "joint {} `{}` at {:.1}°, {:.1}° past {:.1}°",
                i + 1,
                robot.joints[i].name,
                value.to_degrees(),
                excess.to_degrees(),
                limit.to_degrees()
            )
        })
        .collect();
    let positions =
        if passed.is_empty() { String::new() } else { format!("; {}", passed.join(", ")) };
    let message = format!(
        "action `{}`, segment {}: exceeds the joint limits (peak |q'|/limit {:.3}, |q''|/limit \
         {:.3}{positions})",
        s.action,
        s.segment + 1,
        s.peak_velocity_ratio,
        s.peak_acceleration_ratio
    );
    Warning::on_segment(WarningKind::OverLimits, &s.action, s.segment, message)
}

/// The warning for a segment that missed its goal.
fn missed(s: &SegmentReport) -> Warning {
    let what: Vec<String> = s.errors.iter().filter(|e| !e.within).map(describe).collect();
    let why = if s.stalled { ", stalled" } else { "" };
    let message = format!(
        "action `{}`, segment {}: missed {}{why}",
        s.action,
        s.segment + 1,
        what.join(", ")
    );
    Warning::on_segment(WarningKind::MissedGoal, &s.action, s.segment, message)
}
