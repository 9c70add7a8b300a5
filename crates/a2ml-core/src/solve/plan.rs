//! A whole task: decompose, solve every segment from where the last one really ended, join
//! segments (+Tr within an action, +Se between actions) and report on each.

use super::constrained_rrt::{Chart, constrained_rrt, time_constrained};
use super::qp::{self, Component, QpError, QpOptions, SegmentProblem};
use super::report::{Fallback, Plan, QpStats, SegmentReport, VariableError};
use super::rrt::{RrtError, RrtOptions, RrtStats, TimedPath, rrt_connect, time_parameterise};
use crate::collision::CollisionScene;
use crate::decompose::{
    ArmState, DecomposeError, DecomposeOptions, PlannedAction, PlannedSegment, SegmentPattern,
    decompose, goal_error,
};
use crate::kinematics::{HatState, hat_to_cpsa, ik_cpsa};
use crate::language::{ActionBody, PrimitiveConstraint, SolverChoice, Space, Task, Variable};
use crate::math::{DOF, JointVector, Real, Vector3};
use crate::profile::{BodyFrames, ProfileError, Reference, Role, Sample};
use crate::robot::Robot;
use crate::trajectory::{self, Trajectory, TrajectoryError};

/// Settings of [`plan`].
#[derive(Debug, Clone, Default)]
pub struct PlanOptions {
    /// The decomposition (Opt1/Opt2, action planner, default durations).
    pub decompose: DecomposeOptions,
    /// The velocity QP.
    pub qp: QpOptions,
    /// RRT-Connect (its seed and clearance come from the task and `qp.safety_distance`).
    pub rrt: RrtOptions,
    /// Solver for every segment, overriding the task and its actions.
    pub solver: Option<SolverChoice>,
    /// Output rate (Hz), overriding the task's `settings { rate }`.
    pub rate: Option<Real>,
}

/// How far planning has got, for progress displays.
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    /// Segments solved so far.
    pub done: usize,
    /// Segments in the task.
    pub total: usize,
    /// The action being solved.
    pub action: String,
}

/// Why a task cannot be planned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// The decomposition failed.
    #[error(transparent)]
    Decompose(#[from] DecomposeError),
    /// The output rate is not positive and finite.
    #[error("invalid output rate {rate} Hz: it must be positive and finite")]
    InvalidRate {
        /// The rate asked for (Hz).
        rate: Real,
    },
    /// The solver asked for does not exist yet for this kind of segment.
    #[error(
        "action `{action}`: solver `{}` is not available yet for pattern-{} segments; use \
         `auto`, `qp` or `rrt`",
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

/// [`plan`], calling `progress` after each segment is solved.
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
    let decomposition = decompose(robot, task, &options.decompose)?;
    let task_b = task.in_base_frame(&robot.structure.shoulder_in_base_link);
    let total = decomposition.actions.iter().map(|a| a.segments.len()).sum();
    let mut state = Solver {
        robot,
        task: &task_b,
        options,
        rate,
        q: decomposition.start,
        whole: None,
        segments: Vec::with_capacity(total),
        wrist_reference: Vec::new(),
        notes: Vec::new(),
    };
    for action in &decomposition.actions {
        state.action(action, &mut |done| {
            progress(&Progress { done, total, action: action.name.clone() })
        })?;
    }
    let whole = match state.whole {
        Some(w) => w.resample(rate)?,
        // No action: the arm stays at the start.
        None => Trajectory::new(vec![0.0], vec![decomposition.start], vec![JointVector::zeros()])?,
    };
    let mut warnings = state.notes;
    warnings.extend(state.segments.iter().filter(|s| !s.reached).map(missed));
    warnings.extend(state.segments.iter().filter(|s| !s.path_kept).map(left_path));
    Ok(Plan {
        task: decomposition.task,
        joint_names: robot.joint_names().iter().map(|n| (*n).to_owned()).collect(),
        rate,
        trajectory: whole,
        segments: state.segments,
        wrist_reference: state.wrist_reference,
        safety_distance: options.qp.safety_distance,
        warnings,
    })
}

/// The planning state between actions.
struct Solver<'a> {
    robot: &'a Robot,
    task: &'a Task,
    options: &'a PlanOptions,
    rate: Real,
    /// Where the arm really is: the end of what has been solved.
    q: JointVector,
    whole: Option<Trajectory>,
    segments: Vec<SegmentReport>,
    wrist_reference: Vec<(Real, Vector3)>,
    /// Warnings other than missed goals: fallbacks and stretched durations.
    notes: Vec<String>,
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

    fn rrt_failed(&self, source: RrtError) -> SolveError {
        SolveError::Rrt { action: self.action.name.clone(), segment: self.k, source }
    }
}

impl Solver<'_> {
    /// Solves and joins the action's segments, calling `solved` with the number of segments
    /// solved in the whole plan after each.
    fn action(
        &mut self,
        action: &PlannedAction,
        solved: &mut dyn FnMut(usize),
    ) -> Result<(), SolveError> {
        let scene = CollisionScene::new(&self.task.action_scene(action.index));
        let hard = matches!(
            &self.task.actions[action.index].body,
            ActionBody::Constraints { path: Some(path), .. } if path.hard
        );
        let action_start = self.whole.as_ref().map_or(0.0, Trajectory::end);
        let mut joined: Option<Trajectory> = None;
        let mut last: Option<(Real, Real)> = None; // (start, duration) of the previous segment
        for (k, segment) in action.segments.iter().enumerate() {
            let problem = self.problem(action, k, segment)?;
            let chart = Chart::new(self.robot, &problem);
            // A hard path gives the segments that carry it their path primitives; the
            // decomposition's holds are kept as exactly by every solver, hard or not.
            let carries_path = segment
                .primitives
                .iter()
                .any(|p| matches!(p.constraint, PrimitiveConstraint::Path(_)));
            let job = Job {
                action,
                k,
                segment,
                problem,
                scene: &scene,
                chart,
                hard: hard && carries_path,
            };
            let solution = self.solve(&job)?;
            let duration = solution.trajectory.duration();
            let (start, next) = match (joined.take(), last) {
                (Some(before), Some((prev_start, prev_duration))) => {
                    let overlap = self.task.settings.transition * prev_duration.min(duration);
                    let start = prev_start + prev_duration - overlap;
                    (start, trajectory::join_transitional(&before, &solution.trajectory, overlap)?)
                }
                _ => (action_start, shifted(&solution.trajectory, action_start)?),
            };
            joined = Some(next);
            last = Some((start, duration));
            if let Some(end) = solution.trajectory.positions().last() {
                self.q = *end;
            }
            self.reference(&job.problem, start);
            let report = self.report(&job, &solution, start);
            self.segments.push(report);
            solved(self.segments.len());
        }
        if let Some(action_trajectory) = joined {
            self.whole = Some(match self.whole.take() {
                Some(before) => trajectory::join_sequential(&before, &action_trajectory)?,
                None => action_trajectory,
            });
        }
        Ok(())
    }

    /// Solves one segment with its solver: the override, else its own choice. `rrt` plans a
    /// goal segment (pattern 2) in joint space and a segment with a path (patterns 1 and 3) in
    /// its constrained space. `auto` (docs/design.md §5) gives a goal segment among obstacles to
    /// the RRT, falling back to the QP with a warning when the RRT finds no path; it gives a
    /// mixed segment (pattern 3) to the QP and, when the QP stalls, misses the goal or leaves
    /// a hard path, to the constrained RRT, keeping the QP's closest result with a warning
    /// when that fails too; and every other segment to the QP.
    fn solve(&mut self, job: &Job) -> Result<Solved, SolveError> {
        let pattern = job.segment.pattern;
        let kept = |this: &mut Self, source: RrtError, why: &str| {
            let name = job.name();
            this.notes.push(format!("{name}: {why}; rrt: {source}; the QP's result is kept"));
        };
        match self.options.solver.unwrap_or(job.segment.solver) {
            SolverChoice::Qp => self.qp(job),
            SolverChoice::Auto if pattern == SegmentPattern::Goal && !job.scene.is_empty() => {
                match self.rrt(job) {
                    Ok(solved) => Ok(solved),
                    Err(SolveError::Rrt { source, .. }) => {
                        kept(self, source, "a goal segment among obstacles");
                        self.qp(job)
                    }
                    Err(e) => Err(e),
                }
            }
            SolverChoice::Auto if pattern == SegmentPattern::Mixed => {
                let qp = self.qp(job)?;
                let why = match (qp.reached, qp.path_kept, qp.stalled) {
                    (true, true, _) => return Ok(qp),
                    (_, false, _) => Fallback::QpLeftPath,
                    (_, _, true) => Fallback::QpStalled,
                    _ => Fallback::QpMissedGoal,
                };
                match self.constrained(job) {
                    Ok(rrt) if rrt.reached && rrt.path_kept => {
                        Ok(Solved { fallback: Some(why), ..rrt })
                    }
                    Ok(_) => {
                        self.notes.push(format!(
                            "{}: {}; rrt did not do better; the QP's result is kept",
                            job.name(),
                            why.describe()
                        ));
                        Ok(qp)
                    }
                    Err(SolveError::Rrt { source, .. }) => {
                        kept(self, source, why.describe());
                        Ok(qp)
                    }
                    Err(e) => Err(e),
                }
            }
            SolverChoice::Auto => self.qp(job),
            SolverChoice::Rrt if pattern == SegmentPattern::Goal => self.rrt(job),
            SolverChoice::Rrt => self.constrained(job),
            solver => Err(SolveError::UnsupportedSolver {
                action: job.action.name.clone(),
                solver,
                pattern,
            }),
        }
    }

    fn qp(&self, job: &Job) -> Result<Solved, SolveError> {
        let solution =
            qp::solve_segment(self.robot, job.scene, &job.problem, &self.q, &self.options.qp)
                .map_err(|source| SolveError::Qp {
                    action: job.action.name.clone(),
                    segment: job.k,
                    source,
                })?;
        let (path_errors, path_kept) = self.assess(job, &solution.trajectory);
        Ok(Solved {
            solver: SolverChoice::Qp,
            trajectory: solution.trajectory,
            errors: solution.errors,
            path_errors,
            path_kept,
            settle: solution.settle,
            reached: solution.reached,
            stalled: solution.stalled,
            qp: solution.stats,
            rrt: None,
            fallback: None,
        })
    }

    /// A goal segment by RRT-Connect in joint space towards the IK branches of its end state
    /// (the decomposition's configuration first), timed with the bell profile.
    fn rrt(&mut self, job: &Job) -> Result<Solved, SolveError> {
        let end = job.segment.end;
        let mut goals = vec![end];
        if let Ok(state) = ArmState::at(self.robot, &end) {
            if let Ok(branches) = ik_cpsa(self.robot, &state.cpsa, Some(&end)) {
                goals.extend(branches.into_iter().filter(|q| (q - end).amax() > 1e-9));
            }
        }
        let path = rrt_connect(self.robot, job.scene, &self.q, &goals, &self.rrt_options())
            .map_err(|e| job.rrt_failed(e))?;
        let rate = 1.0 / self.options.qp.step;
        let timed = time_parameterise(self.robot, &path.waypoints, job.segment.duration, rate)?;
        Ok(self.timed(job, timed, path.stats))
    }

    /// A segment with a path by RRT-Connect in its constrained space, timed with the bell
    /// profile along the chart path.
    fn constrained(&mut self, job: &Job) -> Result<Solved, SolveError> {
        let options = self.rrt_options();
        let path = constrained_rrt(self.robot, job.scene, &job.chart, &self.q, &options)
            .map_err(|e| job.rrt_failed(e))?;
        let rate = 1.0 / self.options.qp.step;
        let timed = time_constrained(self.robot, &job.chart, &path, job.segment.duration, rate)
            .map_err(|e| job.rrt_failed(e))?;
        Ok(self.timed(job, timed, path.stats))
    }

    fn rrt_options(&self) -> RrtOptions {
        RrtOptions {
            seed: self.task.settings.seed,
            clearance: self.options.qp.safety_distance,
            ..self.options.rrt
        }
    }

    /// An RRT path as solved: the stretch noted, the end's errors.
    fn timed(&mut self, job: &Job, timed: TimedPath, stats: RrtStats) -> Solved {
        if timed.stretched {
            self.notes.push(format!(
                "{}: the rrt path takes {:.2} s instead of {:.2} s to keep every joint within \
                 its speed limit",
                job.name(),
                timed.duration,
                job.segment.duration
            ));
        }
        let end = timed.trajectory.positions().last().copied().unwrap_or(self.q);
        let errors = end_errors(self.robot, &job.problem, &end);
        let tolerance = &self.options.qp.tolerance;
        let reached =
            job.problem.components.iter().zip(errors).all(|(c, e)| e <= tolerance.of(c.variable));
        let (path_errors, path_kept) = self.assess(job, &timed.trajectory);
        Solved {
            solver: SolverChoice::Rrt,
            trajectory: timed.trajectory,
            errors,
            path_errors,
            path_kept,
            settle: 0.0,
            reached,
            stalled: false,
            qp: QpStats::default(),
            rrt: Some(stats),
            fallback: None,
        }
    }

    /// The largest distance of each path component from its path over the trajectory, and
    /// whether a hard path was kept within tolerance.
    fn assess(&self, job: &Job, trajectory: &Trajectory) -> ([Real; 3], bool) {
        let tolerance = &self.options.qp.tolerance;
        let mut worst = [0.0; 3];
        for q in trajectory.positions() {
            let Ok(state) = ArmState::at(self.robot, q) else {
                return ([Real::INFINITY; 3], !job.hard);
            };
            for (w, e) in worst.iter_mut().zip(job.chart.deviation(&state, tolerance)) {
                *w = Real::max(*w, e);
            }
        }
        let within =
            job.problem.components.iter().zip(worst).all(|(c, e)| e <= tolerance.of(c.variable));
        (worst, within || !job.hard)
    }

    /// The segment's references, starting from where the arm really is.
    fn problem(
        &self,
        action: &PlannedAction,
        k: usize,
        segment: &PlannedSegment,
    ) -> Result<SegmentProblem, SolveError> {
        let failed =
            |source| SolveError::Reference { action: action.name.clone(), segment: k, source };
        let state = ArmState::at(self.robot, &self.q).map_err(|e| SolveError::Qp {
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

    /// Appends the segment's reference Pw at the output rate, in plan time.
    fn reference(&mut self, problem: &SegmentProblem, start: Real) {
        for t in trajectory::sample_times(0.0, problem.duration, self.rate) {
            if let Some(p) = reference_wrist(self.robot, problem, t) {
                self.wrist_reference.push((start + t, p));
            }
        }
    }

    fn report(&self, job: &Job, solution: &Solved, start: Real) -> SegmentReport {
        let tolerance = &self.options.qp.tolerance;
        let error = |variable: Variable, error: Real| VariableError {
            variable,
            error,
            within: error <= tolerance.of(variable),
        };
        let components = job.problem.components.iter();
        let errors = components.clone().zip(solution.errors).map(|(c, e)| error(c.variable, e));
        let path_errors = components
            .zip(solution.path_errors)
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
            start,
            end: start + solution.trajectory.duration(),
            duration: segment.duration,
            settle: solution.settle,
            errors: errors.collect(),
            path_errors,
            hard_path: job.hard,
            path_kept: solution.path_kept,
            clearance: trajectory::min_clearance(&solution.trajectory, self.robot, job.scene),
            limit_margin: limit_margin(self.robot, &solution.trajectory),
            stalled: solution.stalled,
            reached: solution.reached,
            qp: solution.qp,
            rrt: solution.rrt,
            fallback: solution.fallback,
        }
    }
}

/// A segment as one of the solvers solved it.
struct Solved {
    solver: SolverChoice,
    /// From time 0.
    trajectory: Trajectory,
    errors: [Real; 3],
    /// Largest distance of each component from its path (0 for goals).
    path_errors: [Real; 3],
    /// The path kept within tolerance, or not hard.
    path_kept: bool,
    settle: Real,
    reached: bool,
    stalled: bool,
    qp: QpStats,
    rrt: Option<RrtStats>,
    /// Why `auto` went on from the QP to this solver.
    fallback: Option<Fallback>,
}

/// Each component's error at configuration `q` against its reference's end: distance for
/// Pw, geodesic angle for rotations, (wrapped) angle difference.
fn end_errors(robot: &Robot, problem: &SegmentProblem, q: &JointVector) -> [Real; 3] {
    let Ok(state) = ArmState::at(robot, q) else { return [Real::INFINITY; 3] };
    problem.components.map(|c| goal_error(&state, &[(c.variable, c.reference.end())]))
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
fn left_path(s: &SegmentReport) -> String {
    let what: Vec<String> = s.path_errors.iter().filter(|e| !e.within).map(describe).collect();
    format!(
        "action `{}`, segment {}: left its hard path: {}",
        s.action,
        s.segment + 1,
        what.join(", ")
    )
}

/// "Pw by 3.1 mm", "θsw by 2.00°".
fn describe(e: &VariableError) -> String {
    match e.variable {
        Variable::Pw => format!("Pw by {:.1} mm", e.error * 1e3),
        v => format!("{} by {:.2}°", v.symbol(), e.error.to_degrees()),
    }
}

/// The warning for a segment that missed its goal.
fn missed(s: &SegmentReport) -> String {
    let what: Vec<String> = s.errors.iter().filter(|e| !e.within).map(describe).collect();
    let why = if s.stalled { ", stalled" } else { "" };
    format!("action `{}`, segment {}: missed {}{why}", s.action, s.segment + 1, what.join(", "))
}
