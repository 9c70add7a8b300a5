//! A whole task: decompose, solve every segment from where the last one really ended, join
//! segments (+Tr within an action, +Se between actions) and report on each.

use super::qp::{self, Component, QpError, QpOptions, SegmentProblem};
use super::report::{Plan, QpStats, SegmentReport, VariableError};
use super::rrt::{RrtError, RrtOptions, RrtStats, rrt_connect, time_parameterise};
use crate::collision::CollisionScene;
use crate::decompose::{
    ArmState, DecomposeError, DecomposeOptions, PlannedAction, PlannedSegment, SegmentPattern,
    decompose, goal_error,
};
use crate::kinematics::{HatState, hat_to_cpsa, ik_cpsa};
use crate::language::{PrimitiveConstraint, SolverChoice, Space, Task, Variable};
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
        "action `{action}`: solver `{}` is not available yet for pattern-{} segments; use `qp` \
         or `auto`{}",
        solver.name(),
        pattern.number(),
        if *solver == SolverChoice::Rrt { " (rrt plans goal segments, pattern 2, so far)" } else { "" }
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

impl Solver<'_> {
    /// Solves and joins the action's segments, calling `solved` with the number of segments
    /// solved in the whole plan after each.
    fn action(
        &mut self,
        action: &PlannedAction,
        solved: &mut dyn FnMut(usize),
    ) -> Result<(), SolveError> {
        let scene = CollisionScene::new(&self.task.action_scene(action.index));
        let action_start = self.whole.as_ref().map_or(0.0, Trajectory::end);
        let mut joined: Option<Trajectory> = None;
        let mut last: Option<(Real, Real)> = None; // (start, duration) of the previous segment
        for (k, segment) in action.segments.iter().enumerate() {
            let problem = self.problem(action, k, segment)?;
            let solution = self.solve(action, k, segment, &problem, &scene)?;
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
            self.reference(&problem, start);
            let report = self.report(action, k, segment, &problem, &solution, &scene, start);
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

    /// Solves one segment with its solver: the override, else its own choice. `auto`
    /// (DESIGN.md §5) gives a goal segment among obstacles to the RRT, falling back to the QP
    /// with a warning when the RRT finds no path, and every other segment to the QP.
    fn solve(
        &mut self,
        action: &PlannedAction,
        k: usize,
        segment: &PlannedSegment,
        problem: &SegmentProblem,
        scene: &CollisionScene,
    ) -> Result<Solved, SolveError> {
        let goal = segment.pattern == SegmentPattern::Goal;
        match self.options.solver.unwrap_or(segment.solver) {
            SolverChoice::Qp => self.qp(action, k, problem, scene),
            SolverChoice::Auto if goal && !scene.is_empty() => {
                match self.rrt(action, k, segment, problem, scene) {
                    Ok(solved) => Ok(solved),
                    Err(SolveError::Rrt { source, .. }) => {
                        self.notes.push(format!(
                            "action `{}`, segment {}: rrt: {source}; the QP's result is kept",
                            action.name,
                            k + 1
                        ));
                        self.qp(action, k, problem, scene)
                    }
                    Err(e) => Err(e),
                }
            }
            SolverChoice::Auto => self.qp(action, k, problem, scene),
            SolverChoice::Rrt if goal => self.rrt(action, k, segment, problem, scene),
            solver => Err(SolveError::UnsupportedSolver {
                action: action.name.clone(),
                solver,
                pattern: segment.pattern,
            }),
        }
    }

    fn qp(
        &self,
        action: &PlannedAction,
        k: usize,
        problem: &SegmentProblem,
        scene: &CollisionScene,
    ) -> Result<Solved, SolveError> {
        let solution = qp::solve_segment(self.robot, scene, problem, &self.q, &self.options.qp)
            .map_err(|source| SolveError::Qp { action: action.name.clone(), segment: k, source })?;
        Ok(Solved {
            solver: SolverChoice::Qp,
            trajectory: solution.trajectory,
            errors: solution.errors,
            max_errors: solution.max_errors,
            settle: solution.settle,
            reached: solution.reached,
            stalled: solution.stalled,
            qp: solution.stats,
            rrt: None,
        })
    }

    /// A goal segment by RRT-Connect in joint space towards the IK branches of its end state
    /// (the decomposition's configuration first), timed with the bell profile.
    fn rrt(
        &mut self,
        action: &PlannedAction,
        k: usize,
        segment: &PlannedSegment,
        problem: &SegmentProblem,
        scene: &CollisionScene,
    ) -> Result<Solved, SolveError> {
        let mut goals = vec![segment.end];
        if let Ok(state) = ArmState::at(self.robot, &segment.end) {
            if let Ok(branches) = ik_cpsa(self.robot, &state.cpsa, Some(&segment.end)) {
                goals.extend(branches.into_iter().filter(|q| (q - segment.end).amax() > 1e-9));
            }
        }
        let options = RrtOptions {
            seed: self.task.settings.seed,
            clearance: self.options.qp.safety_distance,
            ..self.options.rrt
        };
        let failed = |source| SolveError::Rrt { action: action.name.clone(), segment: k, source };
        let path = rrt_connect(self.robot, scene, &self.q, &goals, &options).map_err(failed)?;
        let timed = time_parameterise(
            self.robot,
            &path.waypoints,
            segment.duration,
            1.0 / self.options.qp.step,
        )?;
        if timed.stretched {
            self.notes.push(format!(
                "action `{}`, segment {}: the rrt path takes {:.2} s instead of {:.2} s to keep \
                 every joint within its speed limit",
                action.name,
                k + 1,
                timed.duration,
                segment.duration
            ));
        }
        let end = timed.trajectory.positions().last().copied().unwrap_or(self.q);
        let errors = end_errors(self.robot, problem, &end);
        let tolerance = &self.options.qp.tolerance;
        let reached =
            problem.components.iter().zip(errors).all(|(c, e)| e <= tolerance.of(c.variable));
        Ok(Solved {
            solver: SolverChoice::Rrt,
            trajectory: timed.trajectory,
            errors,
            max_errors: errors,
            settle: 0.0,
            reached,
            stalled: false,
            qp: QpStats::default(),
            rrt: Some(path.stats),
        })
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

    #[allow(clippy::too_many_arguments)]
    fn report(
        &self,
        action: &PlannedAction,
        k: usize,
        segment: &PlannedSegment,
        problem: &SegmentProblem,
        solution: &Solved,
        scene: &CollisionScene,
        start: Real,
    ) -> SegmentReport {
        let tolerance = &self.options.qp.tolerance;
        let error = |variable: Variable, error: Real| VariableError {
            variable,
            error,
            within: error <= tolerance.of(variable),
        };
        let components = problem.components.iter();
        let errors = components.clone().zip(solution.errors).map(|(c, e)| error(c.variable, e));
        let path_errors = components
            .zip(solution.max_errors)
            .filter(|(c, _)| c.role == Role::Path)
            .map(|(c, e)| error(c.variable, e))
            .collect();
        SegmentReport {
            action: action.name.clone(),
            action_index: action.index,
            segment: k,
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
            clearance: trajectory::min_clearance(&solution.trajectory, self.robot, scene),
            limit_margin: limit_margin(self.robot, &solution.trajectory),
            stalled: solution.stalled,
            reached: solution.reached,
            qp: solution.qp,
            rrt: solution.rrt,
        }
    }
}

/// A segment as one of the solvers solved it.
struct Solved {
    solver: SolverChoice,
    /// From time 0.
    trajectory: Trajectory,
    errors: [Real; 3],
    max_errors: [Real; 3],
    settle: Real,
    reached: bool,
    stalled: bool,
    qp: QpStats,
    rrt: Option<RrtStats>,
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

/// The warning for a segment that missed its goal.
fn missed(s: &SegmentReport) -> String {
    let what: Vec<String> = s
        .errors
        .iter()
        .filter(|e| !e.within)
        .map(|e| match e.variable {
            Variable::Pw => format!("Pw by {:.1} mm", e.error * 1e3),
            v => format!("{} by {:.2}°", v.symbol(), e.error.to_degrees()),
        })
        .collect();
    let why = if s.stalled { ", stalled" } else { "" };
    format!("action `{}`, segment {}: missed {}{why}", s.action, s.segment + 1, what.join(", "))
}
