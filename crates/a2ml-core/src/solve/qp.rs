//! The velocity QP of paper eq. 7 (docs/design.md §5): one segment, one small QP per control step.
//!
//! At each step the joint velocity q' minimises ½‖W(J q' - V)‖² + ½λ‖q'‖², J = J_cs or J_tr,
//! V = reference velocity + gain × state error, subject to joint velocity bounds that brake
//! before the position limits and one velocity-damper row per arm-obstacle pair inside the
//! influence distance. J is square, so the unconstrained minimiser almost always tracks V
//! exactly; when it already satisfies every bound and row it is the QP's solution. When some
//! bind, the dual active-set method of Goldfarb and Idnani (`qp::dual`) on the same Cholesky
//! factor solves the step exactly in finitely many steps; Clarabel only confirms or solves the
//! steps it reports infeasible or degenerate (counted in [`QpStats::clarabel_steps`]).
//! Clarabel is used here only.
//!
//! The QP is a [`Resolver`] of the shared control loop ([`super::control`]), which settles,
//! detects stalls and brakes (by holding the state reached). The arm's velocity does not jump
//! to each step's answer: the answer is bounded by the acceleration limits around the
//! velocity the arm has (a box within the velocity box), and the velocity ramps to it over
//! the step, so q is integrated by the trapezoidal rule ([`Integration::Trapezoid`]) and the
//! samples' q and q' are one piecewise-quadratic motion whose acceleration is within the
//! limits. Where that box and an obstacle's damper row cannot both hold, the step keeps the
//! damper (safety first) and the acceleration check of the plan catches the rest.

use std::time::Instant;

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

mod dual;

use super::control::{
    ControlError, ControlOptions, Integration, Resolved, Resolver, run_monitored,
};
use super::judge;
use super::monitor::Monitor;
use super::problem::width;
pub use super::problem::{Component, SegmentProblem};
use super::report::{QpStats, Tolerance};
use crate::collision::{Closest, CollisionModel, CollisionScene, Pair};
use crate::kinematics::{
    ArmPose, KinematicsError, cpsa_jacobian, cpsa_state, hat_jacobian, hat_state, point_jacobian,
};
use crate::language::{Space, Target, Variable};
use crate::math::{DOF, JointVector, Matrix7, Real, Vector7, rotation_log};
use crate::profile::{Reference, Role, Sample, WeightOptions, WeightSchedule};
use crate::robot::Robot;
use crate::spelling::spelled;
use crate::trajectory::{Trajectory, TrajectoryError};

/// Settings of the velocity QP.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct QpOptions {
    /// Internal control step (s), default 2 ms.
    pub step: Real,
    /// Feedback gain on the state error (1/s), default 20.
    pub gain: Real,
    /// Weights of the task components.
    pub weights: WeightOptions,
    /// λ, the regularisation of ‖q'‖² that keeps the step bounded near singularities.
    pub regularization: Real,
    /// Joints stay this far inside their position limits (rad), default 1e-3.
    pub limit_margin: Real,
    /// Braking gain towards a position limit (1/s): q' ≤ k (q_max - margin - q), default 10.
    pub limit_gain: Real,
    /// Fraction of each joint's speed limit the QP may use, default 0.99 (the rest absorbs
    /// interpolation between samples).
    pub velocity_fraction: Real,
    /// Fraction of each joint's acceleration limit a step's velocity change may use, default
    /// 0.9 (the rest absorbs the interpolation of the output between samples).
    pub acceleration_fraction: Real,
    /// The acceleration limits used: the robot's times this, default 1 (the task's
    /// `acceleration` setting).
    pub acceleration_scale: Real,
    /// d_s, the distance kept from obstacles (m), default 0.01.
    pub safety_distance: Real,
    /// d_i, the influence distance where damper rows start (m), default 0.08.
    pub influence: Real,
    /// ξ, the damper's approach speed at the influence distance (m/s), default 0.5.
    pub damper_speed: Real,
    /// Longest time run past the reference's end to settle on the goal (s), default 1.
    pub max_settle: Real,
    /// Joint speed under which the arm counts as at rest (rad/s), default 5e-4.
    pub rest_speed: Real,
    /// When the goal counts as reached.
    pub tolerance: Tolerance,
    /// Keep the path components on their path as constraints, not weighted rows: the
    /// segment's path is hard. Their velocity normal to the path is then the feedback towards
    /// it, so the arm moves along the path or stops on it, giving up progress and the goals
    /// instead (paper §6.2); a step whose bounds and damper rows leave no such velocity keeps
    /// them and lets the path go (the judgement of the result reports it). Default false;
    /// [`super::plan`] sets it for the segments that carry an action's hard path.
    pub hard_path: bool,
}

impl Default for QpOptions {
    fn default() -> Self {
        Self {
            step: 0.002,
            gain: 20.0,
            weights: WeightOptions::default(),
            regularization: 1e-6,
            limit_margin: 1e-3,
            limit_gain: 10.0,
            velocity_fraction: 0.99,
            acceleration_fraction: 0.9,
            acceleration_scale: 1.0,
            safety_distance: 0.01,
            influence: 0.08,
            damper_speed: 0.5,
            max_settle: 1.0,
            rest_speed: 5e-4,
            tolerance: Tolerance::default(),
            hard_path: false,
        }
    }
}

/// Half the width of the slab a·x ∈ [b - ε, b + ε] each equality of a hard path is written
/// as (m/s or rad/s): negligible against the feedback towards the path, thick enough for the
/// interior-point solver's tolerances.
const PATH_SLACK: Real = 1e-6;
/// Step in σ of the central difference giving the path's tangent.
const TANGENT_STEP: Real = 1e-6;

/// Why a segment cannot be solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum QpError {
    /// The settings are out of range.
    #[error("invalid QP settings: {reason}")]
    InvalidOptions {
        /// What is wrong.
        reason: &'static str,
    },
    /// The representation space is singular where the arm is.
    #[error("at t = {time:.3} s: {source}")]
    Singular {
        /// Segment time (s).
        time: Real,
        /// The singularity.
        source: KinematicsError,
    },
    /// Clarabel found no solution of a step's QP.
    #[error("at t = {time:.3} s the QP has no solution (Clarabel: {status})")]
    Unsolved {
        /// Segment time (s).
        time: Real,
        /// Clarabel's status.
        status: ClarabelStatus,
    },
    /// Clarabel refused the step's problem or its update (a shape or value it cannot take).
    #[error("at t = {time:.3} s Clarabel refused the QP: {reason}")]
    Refused {
        /// Segment time (s).
        time: Real,
        /// Clarabel's message.
        reason: String,
    },
    /// Clarabel refused the settings this solver gives it, which are fixed: a bug in a2ml or
    /// a Clarabel that validates them differently.
    #[error("Clarabel refused the QP's settings: {reason}")]
    Settings {
        /// Clarabel's message.
        reason: String,
    },
    /// The state where the arm stopped cannot be held.
    #[error("the state where the arm stopped cannot be held: {reason}")]
    Hold {
        /// Why.
        reason: String,
    },
    /// The wall-clock limit set by the user passed.
    #[error("timeout at t = {time:.3} s: the time limit passed")]
    Timeout {
        /// Segment time (s).
        time: Real,
    },
    /// The samples do not make a trajectory (non-finite values).
    #[error(transparent)]
    Trajectory(#[from] TrajectoryError),
    /// The control loop refused its settings or its run.
    #[error(transparent)]
    Control(ControlError),
}

impl From<ControlError> for QpError {
    fn from(e: ControlError) -> Self {
        match e {
            ControlError::InvalidOptions { reason } => QpError::InvalidOptions { reason },
            ControlError::Timeout { time } => QpError::Timeout { time },
            ControlError::Trajectory(e) => QpError::Trajectory(e),
            e => QpError::Control(e),
        }
    }
}

/// A solved segment.
#[derive(Debug, Clone, PartialEq)]
pub struct QpSolution {
    /// The internal steps: time from 0 (s), q, q'.
    pub trajectory: Trajectory,
    /// Final error of each component against its reference's end (m or rad).
    pub errors: [Real; 3],
    /// Largest error of each component against its reference over the segment (m or rad).
    pub max_errors: [Real; 3],
    /// Time run past T to settle (s).
    pub settle: Real,
    /// Every component within tolerance at the end.
    pub reached: bool,
    /// Progress stopped short of the goal.
    pub stalled: bool,
    /// Counters and timings.
    pub stats: QpStats,
}

/// Solves `problem` from configuration `q0` among the obstacles of `scene`.
///
/// # Errors
/// [`QpError`]: invalid settings, a singular representation along the way, or a step that
/// Clarabel cannot solve.
pub fn solve_segment(
    robot: &Robot,
    scene: &CollisionScene,
    problem: &SegmentProblem,
    q0: &JointVector,
    options: &QpOptions,
) -> Result<QpSolution, QpError> {
    solve_segment_monitored(robot, scene, problem, q0, options, &mut Monitor::silent())
}

/// [`solve_segment`], reporting the fraction of the reference's time done to `monitor` and
/// stopping at its deadline ([`QpError::Timeout`]).
///
/// # Errors
/// As [`solve_segment`].
pub fn solve_segment_monitored(
    robot: &Robot,
    scene: &CollisionScene,
    problem: &SegmentProblem,
    q0: &JointVector,
    options: &QpOptions,
    monitor: &mut Monitor,
) -> Result<QpSolution, QpError> {
    check_options(options)?;
    let mut controller = Controller::new(robot, scene, problem.clone(), options);
    let run = run_monitored(
        robot,
        &mut controller,
        q0,
        problem.duration,
        &control_options(options),
        monitor,
    )?;
    let errors = controller.errors;
    Ok(QpSolution {
        trajectory: run.trajectory,
        errors,
        max_errors: controller.max_errors,
        settle: run.settle,
        reached: judge::reached(&options.tolerance, &problem.components, &errors),
        stalled: run.stalled,
        stats: controller.timing.stats(),
    })
}

/// The control loop the QP runs on: its step, settle time, rest speed and tolerance; a stall
/// is a fall of less than 1 % in 0.2 s, as for every resolver.
fn control_options(o: &QpOptions) -> ControlOptions {
    ControlOptions {
        step: o.step,
        integration: Integration::Trapezoid,
        max_settle: o.max_settle,
        rest_speed: o.rest_speed,
        // Unused: the QP brakes by holding the state it reached.
        brake_rate: 0.5 / o.step,
        start_ramp: 0.0,
        tolerance: o.tolerance,
        ..ControlOptions::default()
    }
}

fn check_options(o: &QpOptions) -> Result<(), QpError> {
    let positive = |x: Real| x.is_finite() && x > 0.0;
    let checks = [
        (positive(o.step), "the step must be positive"),
        (positive(o.gain) && o.gain * o.step < 1.0, "the gain must be positive and below 1/step"),
        (o.regularization.is_finite() && o.regularization >= 0.0, "negative regularisation"),
        (o.limit_margin.is_finite() && o.limit_margin >= 0.0, "negative limit margin"),
        (positive(o.limit_gain) && o.limit_gain * o.step <= 1.0, "limit gain out of range"),
        (positive(o.velocity_fraction) && o.velocity_fraction <= 1.0, "velocity fraction"),
        (
            positive(o.acceleration_fraction) && o.acceleration_fraction <= 1.0,
            "acceleration fraction",
        ),
        (positive(o.acceleration_scale), "the acceleration scale must be positive"),
        (o.safety_distance.is_finite() && o.safety_distance >= 0.0, "negative safety distance"),
        (o.influence.is_finite() && o.influence > o.safety_distance, "influence <= safety"),
        (positive(o.damper_speed), "the damper speed must be positive"),
        (o.max_settle.is_finite() && o.max_settle >= 0.0, "negative settle time"),
        (positive(o.rest_speed), "the rest speed must be positive"),
    ];
    match checks.iter().find(|(ok, _)| !ok) {
        Some((_, reason)) => Err(QpError::InvalidOptions { reason }),
        None => Ok(()),
    }
}

/// The result of one control step.
struct Step {
    velocity: JointVector,
    errors: [Real; 3],
}

/// The QP as a resolver: what stays the same over a segment's steps, the solver it sets up
/// once, and what it measured.
struct Controller<'a> {
    robot: &'a Robot,
    /// The segment's problem; once the loop stops while moving, the hold of where it stopped.
    problem: SegmentProblem,
    /// The segment's own components, whose hard path holds while braking too.
    path: [Component; 3],
    options: &'a QpOptions,
    weights: WeightSchedule,
    lower: JointVector,
    upper: JointVector,
    speed: JointVector,
    /// The acceleration each step may use (rad/s²).
    acceleration: JointVector,
    /// Created at the first step the dual method leaves to Clarabel.
    clarabel: Option<Clarabel>,
    /// The arm and scene: the clearance that tells when no pair is inside the influence
    /// distance, and the closest points of those that are.
    model: CollisionModel,
    timing: Timing,
    /// The component errors at the last step of the segment's own problem.
    errors: [Real; 3],
    /// The largest error of each component over the segment's own steps.
    max_errors: [Real; 3],
    /// Holding the state where the loop stopped (its errors are not the segment's).
    holding: bool,
}

impl<'a> Controller<'a> {
    fn new(
        robot: &'a Robot,
        scene: &'a CollisionScene,
        problem: SegmentProblem,
        options: &'a QpOptions,
    ) -> Self {
        Self {
            robot,
            weights: WeightSchedule::new(problem.duration, options.weights),
            path: problem.components,
            problem,
            options,
            lower: robot.lower(),
            upper: robot.upper(),
            speed: robot.velocity_limits() * options.velocity_fraction,
            acceleration: robot.acceleration_limits()
                * (options.acceleration_scale * options.acceleration_fraction),
            clarabel: None,
            model: CollisionModel::new(robot, scene),
            timing: Timing::default(),
            errors: [Real::INFINITY; 3],
            max_errors: [0.0; 3],
            holding: false,
        }
    }

    /// The velocity to ramp to over the step from `q` (at `pose`), where the arm moves at
    /// `current`.
    fn step(
        &mut self,
        pose: &ArmPose,
        q: &JointVector,
        current: &JointVector,
        t: Real,
    ) -> Result<Step, QpError> {
        let started = Instant::now();
        let singular = |source| QpError::Singular { time: t, source };
        let (jacobian, values) = self.measure(pose).map_err(singular)?;
        let (target, weights, errors) = self.task(t, &values);

        // ½‖W(J x - V)‖² + ½λ‖x‖²: P = Jᵀ W² J + λ I, c = Jᵀ W² V.
        let weighted = Matrix7::from_diagonal(&weights.component_mul(&weights)) * jacobian;
        let p = jacobian.transpose() * weighted + Matrix7::identity() * self.options.regularization;
        let c = weighted.transpose() * target;
        let (lower, upper) = self.bounds(q);
        let ramp = self.ramp(&lower, &upper, current);
        let mut rows = self.damper_rows(pose, q);
        let dampers = rows.len();
        if self.options.hard_path {
            rows.extend(self.path_rows(&jacobian, &values));
        }
        let (velocity, clarabel) = match self.solve_step(&p, &c, (&lower, &upper), ramp, &rows, t) {
            // No velocity keeps the path within the bounds and the damper rows: keep those.
            Err(_) if rows.len() > dampers => {
                rows.truncate(dampers);
                self.solve_step(&p, &c, (&lower, &upper), ramp, &rows, t)?
            }
            solved => solved?,
        };
        self.timing.record(started.elapsed().as_secs_f64(), clarabel);
        Ok(Step { velocity, errors })
    }

    /// The step QP's solution within the acceleration box `ramp` when it holds with the rows,
    /// else within the velocity box `bounds` (the rows kept); whether Clarabel was needed.
    ///
    /// The dual active-set method ([`dual`]) solves the step exactly; Clarabel only where it
    /// reports the problem infeasible (Clarabel confirms it, or solves what rounding made
    /// look so) or degenerate, and where P has no Cholesky factor (no regularisation, a
    /// singular J).
    fn solve_step(
        &mut self,
        p: &Matrix7,
        c: &Vector7,
        (lower, upper): (&Vector7, &Vector7),
        (ramp_lower, ramp_upper): (Vector7, Vector7),
        rows: &[(Vector7, Real)],
        t: Real,
    ) -> Result<(Vector7, bool), QpError> {
        let cholesky = p.cholesky();
        let exact = |lower: &Vector7, upper: &Vector7| match &cholesky {
            Some(ch) => match dual::solve(ch, c, &dual::Constraints { lower, upper, rows }) {
                dual::Outcome::Solved(solution) => Some(solution.x),
                dual::Outcome::Infeasible | dual::Outcome::Degenerate => None,
            },
            None => None,
        };
        Ok(match exact(&ramp_lower, &ramp_upper) {
            Some(x) => (x, false),
            None => match self.clarabel_solve(p, c, &ramp_lower, &ramp_upper, rows, t) {
                Ok(x) => (x, true),
                // The rows cannot hold within the acceleration box: keep the rows.
                Err(_) => match exact(lower, upper) {
                    Some(x) => (x, false),
                    None => (self.clarabel_solve(p, c, lower, upper, rows, t)?, true),
                },
            },
        })
    }

    /// A hard path as equality rows, each written as the slab a·x ≤ b + ε, -a·x ≤ -b + ε
    /// ([`PATH_SLACK`]): along every direction n normal to the path at the point nearest the
    /// arm (the path components stacked, σ shared), nᵀ J_path q' = gain · nᵀ (nearest - now).
    /// Motion along the path is left to the weighted rows; a path that does not move (a hold)
    /// is kept in every direction. The segment's path, also while the arm brakes.
    fn path_rows(&self, jacobian: &Matrix7, values: &[Target; 3]) -> Vec<(Vector7, Real)> {
        let components = &self.path;
        let mut offsets = [0; 3];
        let mut row = 0;
        for (k, c) in components.iter().enumerate() {
            offsets[k] = row;
            row += width(c.variable);
        }
        let path: Vec<usize> = (0..3).filter(|&k| components[k].role == Role::Path).collect();
        let sigma = path
            .iter()
            .find_map(|&k| components[k].reference.nearest_fraction(&values[k]))
            .map_or(0.0, |s| s.clamp(0.0, 1.0));
        let m: usize = path.iter().map(|&k| width(components[k].variable)).sum();
        let mut jacobian_path = nalgebra::DMatrix::<Real>::zeros(m, DOF);
        let mut error = nalgebra::DVector::<Real>::zeros(m);
        let mut tangent = nalgebra::DVector::<Real>::zeros(m);
        let mut r = 0;
        for &k in &path {
            let c = &components[k];
            let w = width(c.variable);
            let at = |s: Real| c.reference.at_fraction(s);
            let towards = difference(c.variable, &at(sigma), &values[k]);
            let (ahead, behind) = (at(sigma + TANGENT_STEP), at(sigma - TANGENT_STEP));
            let along = difference(c.variable, &ahead, &behind) / (2.0 * TANGENT_STEP);
            for i in 0..w {
                jacobian_path.set_row(r + i, &jacobian.row(offsets[k] + i));
                error[r + i] = towards[i];
                tangent[r + i] = along[i];
            }
            r += w;
        }
        let gain = self.options.gain;
        normal_basis(&tangent)
            .iter()
            .flat_map(|n| {
                let a = Vector7::from_iterator((n.transpose() * &jacobian_path).iter().copied());
                let b = gain * n.dot(&error);
                [(a, b + PATH_SLACK), (-a, -b + PATH_SLACK)]
            })
            .collect()
    }

    /// The Jacobian of the segment's space and the current values of its variables.
    fn measure(&self, pose: &ArmPose) -> Result<(Matrix7, [Target; 3]), KinematicsError> {
        Ok(match self.problem.space {
            Space::Cpsa => {
                let s = cpsa_state(self.robot, pose)?;
                let values =
                    [Target::Position(s.pw), Target::Rotation(s.ow), Target::Angle(s.swivel)];
                (cpsa_jacobian(self.robot, pose)?, values)
            }
            Space::Hat => {
                let s = hat_state(pose)?;
                let values = [
                    Target::Rotation(s.shoulder_frame),
                    Target::Angle(s.elbow_angle),
                    Target::Rotation(s.ow),
                ];
                (hat_jacobian(pose)?, values)
            }
        })
    }

    /// V, the row weights and the component errors at t.
    fn task(&self, t: Real, values: &[Target; 3]) -> (Vector7, Vector7, [Real; 3]) {
        let mut target = Vector7::zeros();
        let mut weights = Vector7::zeros();
        let mut errors = [0.0; 3];
        let gain = self.options.gain;
        let mut row = 0;
        for (slot, component) in self.problem.components.iter().enumerate() {
            let w = self.weights.weight(component.role, t);
            let sample = component.reference.sample(t);
            let width = match (sample, values[slot]) {
                (Sample::Position { value, velocity }, Target::Position(p)) => {
                    let e = value - p;
                    errors[slot] = e.norm();
                    target.fixed_rows_mut::<3>(row).copy_from(&(velocity + e * gain));
                    3
                }
                (Sample::Rotation { value, angular_velocity }, Target::Rotation(r)) => {
                    // Spatial error: the rotation taking R to R_ref, R_ref Rᵀ, as a vector in {b}.
                    let e = rotation_log(&(value * r.inverse()));
                    errors[slot] = e.norm();
                    target.fixed_rows_mut::<3>(row).copy_from(&(angular_velocity + e * gain));
                    3
                }
                (Sample::Angle { value, rate }, Target::Angle(a)) => {
                    let e = component.variable.angle_difference(value, a);
                    errors[slot] = e.abs();
                    target[row] = rate + e * gain;
                    1
                }
                // References are built from the same variables as the values.
                _ => {
                    errors[slot] = Real::INFINITY;
                    width(component.variable)
                }
            };
            for i in row..row + width {
                weights[i] = w;
            }
            row += width;
        }
        (target, weights, errors)
    }

    /// Velocity bounds: the speed limits, braking towards the position limits so that a joint
    /// approaches `limit - margin` exponentially and never steps past it.
    fn bounds(&self, q: &JointVector) -> (Vector7, Vector7) {
        let (margin, k) = (self.options.limit_margin, self.options.limit_gain);
        let mut lower = Vector7::zeros();
        let mut upper = Vector7::zeros();
        for i in 0..DOF {
            // Inside the margin the joint may stay but not go further.
            let room_up = (self.upper[i] - margin - q[i]).max(0.0);
            let room_down = (q[i] - self.lower[i] - margin).max(0.0);
            upper[i] = self.speed[i].min(k * room_up);
            lower[i] = -self.speed[i].min(k * room_down);
        }
        (lower, upper)
    }

    /// The velocity box intersected with what the acceleration limits reach from `current` in
    /// one step. A joint whose braking bound lies beyond that reach brakes as hard as it may.
    fn ramp(&self, lower: &Vector7, upper: &Vector7, current: &JointVector) -> (Vector7, Vector7) {
        let reach = self.acceleration * self.options.step;
        let mut ramp_lower = Vector7::zeros();
        let mut ramp_upper = Vector7::zeros();
        for i in 0..DOF {
            let (lo, hi) = (current[i] - reach[i], current[i] + reach[i]);
            ramp_lower[i] = lower[i].max(lo).min(hi);
            ramp_upper[i] = upper[i].min(hi).max(lo);
        }
        (ramp_lower, ramp_upper)
    }

    /// One row a·x ≤ b per arm-obstacle pair inside the influence distance: the speed at
    /// which the closest points approach, -nᵀ (J_link - J_other) x, is at most
    /// ξ (d - d_s) / (d_i - d_s). The closest points are the model's closed forms
    /// ([`CollisionModel::near_pairs`]).
    fn damper_rows(&self, pose: &ArmPose, q: &JointVector) -> Vec<(Vector7, Real)> {
        let o = self.options;
        let mut near = Vec::new();
        self.model.near_pairs(q, o.influence, &mut near);
        near.iter()
            .map(|p| damper_row(o, &p.normal, &relative_jacobian(self.robot, pose, p), p.distance))
            .collect()
    }

    fn clarabel_solve(
        &mut self,
        p: &Matrix7,
        c: &Vector7,
        lower: &Vector7,
        upper: &Vector7,
        rows: &[(Vector7, Real)],
        t: Real,
    ) -> Result<Vector7, QpError> {
        // Room for the rows present now, grown by doubling: far fewer rows than pairs are
        // ever near at once, and the interior-point cost grows with the rows.
        let mut solver = match self.clarabel.take() {
            Some(s) if s.pair_rows >= rows.len() => s,
            previous => {
                let room = previous.map_or(2, |s| s.pair_rows).max(1);
                let mut capacity = room;
                while capacity < rows.len() {
                    capacity *= 2;
                }
                Clarabel::new(capacity).map_err(|e| e.at(t))?
            }
        };
        let solved = solver.solve(p, c, lower, upper, rows);
        self.clarabel = Some(solver);
        match solved {
            Ok((x, status)) => {
                if status == ClarabelStatus::AlmostSolved {
                    self.timing.almost_solved += 1;
                }
                Ok(x)
            }
            Err(e) => Err(e.at(t)),
        }
    }

    /// A problem holding every variable at its value at `pose` for `duration`.
    fn hold_problem(&self, pose: &ArmPose, duration: Real) -> Result<SegmentProblem, QpError> {
        let (_, values) =
            self.measure(pose).map_err(|source| QpError::Singular { time: 0.0, source })?;
        let hold = |c: &Component, value: Target| -> Result<Component, QpError> {
            let reference = Reference::hold(c.variable, value, duration)
                .map_err(|e| QpError::Hold { reason: e.to_string() })?;
            Ok(Component { variable: c.variable, reference, role: Role::Path })
        };
        let [a, b, c] = &self.problem.components;
        Ok(SegmentProblem {
            space: self.problem.space,
            components: [hold(a, values[0])?, hold(b, values[1])?, hold(c, values[2])?],
            duration,
        })
    }
}

impl Resolver for Controller<'_> {
    type Error = QpError;

    /// The step's answer, its error the largest component error in tolerance units.
    fn resolve(
        &mut self,
        pose: &ArmPose,
        q: &JointVector,
        velocity: &JointVector,
        t: Real,
    ) -> Result<Resolved, QpError> {
        let step = self.step(pose, q, velocity, t)?;
        if !self.holding {
            for (m, e) in self.max_errors.iter_mut().zip(step.errors) {
                *m = Real::max(*m, e);
            }
            self.errors = step.errors;
        }
        let units =
            judge::tolerance_units(&self.options.tolerance, &self.problem.components, &step.errors);
        Ok(Resolved { velocity: step.velocity, error: units.iter().copied().fold(0.0, Real::max) })
    }

    /// The component errors in tolerance units, summed: one number that falls as the arm
    /// approaches the goal.
    fn progress(&self, _: &Resolved) -> Real {
        let units =
            judge::tolerance_units(&self.options.tolerance, &self.problem.components, &self.errors);
        units.iter().sum()
    }

    /// Holds every variable where the arm stopped until it is at rest: braking takes as long
    /// as the acceleration limits ask, at most the settle time plus that.
    fn hold(
        &mut self,
        pose: &ArmPose,
        velocity: &JointVector,
        step: Real,
    ) -> Result<Option<usize>, QpError> {
        let hold = self.hold_problem(pose, self.options.max_settle.max(step))?;
        self.weights = WeightSchedule::new(hold.duration, self.options.weights);
        self.problem = hold;
        self.clarabel = None;
        self.holding = true;
        let settle_steps = (self.options.max_settle / step).ceil() as usize;
        let braking = (velocity.component_div(&self.acceleration).amax() / step).ceil() as usize;
        Ok(Some(settle_steps.max(1) + braking))
    }
}

/// `to - from` in a variable's rows of the Jacobian: the difference of positions, the spatial
/// rotation vector log(to fromᵀ), the angle difference (the swivel angle wrapped); angles
/// in the first entry.
fn difference(variable: Variable, to: &Target, from: &Target) -> crate::math::Vector3 {
    match variable.difference(to, from) {
        Some(d) => d,
        None => crate::math::Vector3::zeros(),
    }
}

/// An orthonormal basis of the directions normal to `tangent`: the last m - 1 columns of the
/// Householder reflection taking the first axis to it (all m axes for a zero tangent).
fn normal_basis(tangent: &nalgebra::DVector<Real>) -> Vec<nalgebra::DVector<Real>> {
    let m = tangent.len();
    let length = tangent.norm();
    if length <= 1e-12 {
        return (0..m)
            .map(|i| nalgebra::DVector::from_fn(m, |j, _| if i == j { 1.0 } else { 0.0 }))
            .collect();
    }
    let u = tangent / length;
    // v = u ∓ e1, the sign that keeps v away from zero.
    let mut v = u.clone();
    v[0] += if u[0] > 0.0 { 1.0 } else { -1.0 };
    let vv = v.norm_squared();
    (1..m)
        .map(|i| {
            let e = nalgebra::DVector::from_fn(m, |j, _| if i == j { 1.0 } else { 0.0 });
            &e - &v * (2.0 * v[i] / vv)
        })
        .collect()
}

/// J_p of the link's closest point, minus that of the other capsule's closest point when the
/// other is a moving link (self-collision).
/// The damper row of a pair at `distance` along `normal` (from the other side to the link),
/// `relative` the Jacobian of the link's closest point relative to the other's.
fn damper_row(
    o: &QpOptions,
    normal: &crate::math::Vector3,
    relative: &crate::math::Jacobian3x7,
    distance: Real,
) -> (Vector7, Real) {
    let a = -(normal.transpose() * relative).transpose();
    let b = o.damper_speed * (distance - o.safety_distance) / (o.influence - o.safety_distance);
    (a, b)
}

fn relative_jacobian(robot: &Robot, pose: &ArmPose, p: &Closest) -> crate::math::Jacobian3x7 {
    let frame = |capsule: usize| robot.capsules[capsule].frame;
    match p.pair {
        Pair::Obstacle { capsule, .. } => point_jacobian(pose, frame(capsule), &p.on_link),
        Pair::SelfPair(k) => {
            let (link, other) = robot.self_pairs[k];
            point_jacobian(pose, frame(link), &p.on_link)
                - point_jacobian(pose, frame(other), &p.on_other)
        }
    }
}

/// A Clarabel solver for the step QP, set up with room for `pair_rows` damper rows and
/// updated in place: 14 bound rows (x ≤ u, -x ≤ -l) then the damper rows, unused ones
/// written as 0·x ≤ 1.
struct Clarabel {
    solver: DefaultSolver<Real>,
    pair_rows: usize,
    p_values: Vec<Real>,
    q_values: Vec<Real>,
    a_values: Vec<Real>,
    b_values: Vec<Real>,
}

/// Why Clarabel gave no answer to a step, before the step's time is known.
#[derive(Debug)]
enum ClarabelFailure {
    Status(ClarabelStatus),
    Refused(String),
    Settings(String),
}

impl ClarabelFailure {
    fn at(self, time: Real) -> QpError {
        match self {
            Self::Status(status) => QpError::Unsolved { time, status },
            Self::Refused(reason) => QpError::Refused { time, reason },
            Self::Settings(reason) => QpError::Settings { reason },
        }
    }
}

/// Clarabel's status at the end of a solve, in a2ml's spelling (Clarabel enters a2ml here
/// only, so its type does not leave this module).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ClarabelStatus {
    /// The solver has not run.
    Unsolved,
    /// Solved to the tolerances.
    Solved,
    /// Primal infeasible: the bounds and damper rows cannot all hold.
    PrimalInfeasible,
    /// Dual infeasible (unbounded): cannot happen with a positive definite P.
    DualInfeasible,
    /// Solved to reduced accuracy.
    AlmostSolved,
    /// Primal infeasible, to reduced accuracy.
    AlmostPrimalInfeasible,
    /// Dual infeasible, to reduced accuracy.
    AlmostDualInfeasible,
    /// The iteration limit passed.
    MaxIterations,
    /// Clarabel's own time limit passed (none is set).
    MaxTime,
    /// A numerical error.
    NumericalError,
    /// No progress.
    InsufficientProgress,
    /// Stopped by a callback (none is set).
    CallbackTerminated,
}

spelled!(
    ClarabelStatus,
    "clarabel status",
    [
        ClarabelStatus::Unsolved,
        ClarabelStatus::Solved,
        ClarabelStatus::PrimalInfeasible,
        ClarabelStatus::DualInfeasible,
        ClarabelStatus::AlmostSolved,
        ClarabelStatus::AlmostPrimalInfeasible,
        ClarabelStatus::AlmostDualInfeasible,
        ClarabelStatus::MaxIterations,
        ClarabelStatus::MaxTime,
        ClarabelStatus::NumericalError,
        ClarabelStatus::InsufficientProgress,
        ClarabelStatus::CallbackTerminated,
    ]
);

impl From<SolverStatus> for ClarabelStatus {
    fn from(status: SolverStatus) -> Self {
        match status {
            SolverStatus::Unsolved => Self::Unsolved,
            SolverStatus::Solved => Self::Solved,
            SolverStatus::PrimalInfeasible => Self::PrimalInfeasible,
            SolverStatus::DualInfeasible => Self::DualInfeasible,
            SolverStatus::AlmostSolved => Self::AlmostSolved,
            SolverStatus::AlmostPrimalInfeasible => Self::AlmostPrimalInfeasible,
            SolverStatus::AlmostDualInfeasible => Self::AlmostDualInfeasible,
            SolverStatus::MaxIterations => Self::MaxIterations,
            SolverStatus::MaxTime => Self::MaxTime,
            SolverStatus::NumericalError => Self::NumericalError,
            SolverStatus::InsufficientProgress => Self::InsufficientProgress,
            SolverStatus::CallbackTerminated => Self::CallbackTerminated,
        }
    }
}

impl Clarabel {
    fn new(pair_rows: usize) -> Result<Self, ClarabelFailure> {
        let m = 2 * DOF + pair_rows;
        // P: the upper triangle of a dense 7x7, column by column.
        let p_colptr: Vec<usize> = (0..=DOF).map(|j| j * (j + 1) / 2).collect();
        let p_rows: Vec<usize> = (0..DOF).flat_map(|j| 0..=j).collect();
        let p_values = vec![0.0; p_rows.len()];
        let p = CscMatrix::new(DOF, DOF, p_colptr, p_rows, p_values.clone());
        // A: column j holds +1 at row j, -1 at row 7 + j, and every damper row.
        let per_column = 2 + pair_rows;
        let a_colptr: Vec<usize> = (0..=DOF).map(|j| j * per_column).collect();
        let a_rows: Vec<usize> =
            (0..DOF).flat_map(|j| [j, DOF + j].into_iter().chain(2 * DOF..m)).collect();
        let a_values: Vec<Real> = (0..DOF)
            .flat_map(|_| [1.0, -1.0].into_iter().chain(std::iter::repeat_n(0.0, pair_rows)))
            .collect();
        let a = CscMatrix::new(m, DOF, a_colptr, a_rows, a_values.clone());
        let b_values = vec![1.0; m];
        let q_values = vec![0.0; DOF];
        let cones = [SupportedConeT::NonnegativeConeT(m)];
        let solver = DefaultSolver::new(&p, &q_values, &a, &b_values, &cones, settings()?)
            .map_err(|e| ClarabelFailure::Refused(e.to_string()))?;
        Ok(Self { solver, pair_rows, p_values, q_values, a_values, b_values })
    }

    fn solve(
        &mut self,
        p: &Matrix7,
        c: &Vector7,
        lower: &Vector7,
        upper: &Vector7,
        rows: &[(Vector7, Real)],
    ) -> Result<(Vector7, ClarabelStatus), ClarabelFailure> {
        let mut k = 0;
        for j in 0..DOF {
            for i in 0..=j {
                self.p_values[k] = p[(i, j)];
                k += 1;
            }
            self.q_values[j] = -c[j];
        }
        let per_column = 2 + self.pair_rows;
        for j in 0..DOF {
            for r in 0..self.pair_rows {
                self.a_values[j * per_column + 2 + r] = rows.get(r).map_or(0.0, |(a, _)| a[j]);
            }
            self.b_values[j] = upper[j];
            self.b_values[DOF + j] = -lower[j];
        }
        for r in 0..self.pair_rows {
            self.b_values[2 * DOF + r] = rows.get(r).map_or(1.0, |(_, b)| *b);
        }
        let update = |s: &mut DefaultSolver<Real>| -> Result<(), String> {
            s.update_P(&self.p_values).map_err(|e| e.to_string())?;
            s.update_q(&self.q_values).map_err(|e| e.to_string())?;
            s.update_A(&self.a_values).map_err(|e| e.to_string())?;
            s.update_b(&self.b_values).map_err(|e| e.to_string())
        };
        update(&mut self.solver).map_err(ClarabelFailure::Refused)?;
        self.solver.solve();
        let solution = &self.solver.solution;
        // The one place Clarabel's outcome is decided. `almost_solved` is accepted: it means
        // the tolerances of 1e-7 were met only to Clarabel's reduced ones (5e-5 to 1e-4 by
        // default), which on a 7-variable velocity step is far below what the control loop
        // corrects at the next 2 ms step; the joint bounds and damper rows are re-checked on
        // the output by the plan, and refusing it would stop a segment over a rounding. The
        // count is kept in [`QpStats::clarabel_almost_solved`].
        match ClarabelStatus::from(solution.status) {
            status @ (ClarabelStatus::Solved | ClarabelStatus::AlmostSolved) => {
                Ok((Vector7::from_column_slice(&solution.x), status))
            }
            status => Err(ClarabelFailure::Status(status)),
        }
    }
}

/// Clarabel tuned for a tiny dense QP solved thousands of times: no presolve or
/// equilibration (they would forbid or distort the in-place updates), structural zeros kept
/// so the sparsity pattern never changes, tolerances of 1e-8.
fn settings() -> Result<DefaultSettings<Real>, ClarabelFailure> {
    DefaultSettingsBuilder::default()
        .verbose(false)
        .presolve_enable(false)
        .equilibrate_enable(false)
        .input_sparse_dropzeros(false)
        .iterative_refinement_enable(false)
        .tol_gap_abs(1e-7)
        .tol_gap_rel(1e-7)
        .tol_feas(1e-7)
        .max_iter(100)
        .build()
        .map_err(|e| ClarabelFailure::Settings(e.to_string()))
}

/// Step timings, split by whether Clarabel was needed.
#[derive(Default)]
struct Timing {
    fast: Vec<Real>,
    clarabel: Vec<Real>,
    almost_solved: usize,
}

impl Timing {
    fn record(&mut self, seconds: Real, clarabel: bool) {
        if clarabel { self.clarabel.push(seconds) } else { self.fast.push(seconds) }
    }

    fn stats(&self) -> QpStats {
        let steps = self.fast.len() + self.clarabel.len();
        let all = self.fast.iter().chain(&self.clarabel);
        let total: Real = all.clone().sum();
        QpStats {
            steps,
            clarabel_steps: self.clarabel.len(),
            clarabel_almost_solved: self.almost_solved,
            mean_step_time: if steps == 0 { 0.0 } else { total / steps as Real },
            worst_step_time: all.fold(0.0, |a, b| a.max(*b)),
            median_fast_time: median(&self.fast),
            median_clarabel_time: median(&self.clarabel),
        }
    }
}

fn median(values: &[Real]) -> Real {
    if values.is_empty() {
        return 0.0;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(Real::total_cmp);
    sorted[sorted.len() / 2]
}

#[cfg(test)]
mod tests {
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    use super::*;
    use crate::collision;

    fn random_problem(rng: &mut StdRng) -> (Matrix7, Vector7) {
        let j = Matrix7::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let w = Vector7::from_fn(|_, _| rng.random_range(0.1..10.0));
        let weighted = Matrix7::from_diagonal(&w.component_mul(&w)) * j;
        let p = j.transpose() * weighted + Matrix7::identity() * 1e-6;
        let v = Vector7::from_fn(|_, _| rng.random_range(-1.0..1.0));
        (p, weighted.transpose() * v)
    }

    fn objective(p: &Matrix7, c: &Vector7, x: &Vector7) -> Real {
        0.5 * x.dot(&(p * x)) - c.dot(x)
    }

    #[test]
    fn clarabel_agrees_with_least_squares_when_nothing_binds() {
        let mut rng = StdRng::seed_from_u64(1);
        let mut solver = Clarabel::new(2).expect("set up");
        for _ in 0..50 {
            let (p, c) = random_problem(&mut rng);
            let exact = p.cholesky().expect("positive definite").solve(&c);
            let bound = Vector7::repeat(10.0 * exact.amax() + 1.0);
            let (x, status) = solver.solve(&p, &c, &-bound, &bound, &[]).expect("solves");
            assert_eq!(status, ClarabelStatus::Solved);
            assert!((x - exact).amax() < 1e-6 * (1.0 + exact.amax()), "{x} vs {exact}");
        }
    }

    #[test]
    fn clarabel_is_feasible_and_no_feasible_point_does_better() {
        let mut rng = StdRng::seed_from_u64(2);
        let mut solver = Clarabel::new(2).expect("set up");
        for _ in 0..30 {
            let (p, c) = random_problem(&mut rng);
            let exact = p.cholesky().expect("positive definite").solve(&c);
            // Bounds at half the unconstrained step, and two rows cutting it off.
            let (upper, lower) = (exact.abs() * 0.5 + Vector7::repeat(0.01), -exact.abs() * 0.5);
            let rows: Vec<(Vector7, Real)> = (0..2)
                .map(|_| (Vector7::from_fn(|_, _| rng.random_range(-1.0..1.0)), 0.01))
                .collect();
            let (x, _) = solver.solve(&p, &c, &lower, &upper, &rows).expect("solves");
            let feasible = |y: &Vector7, tol: Real| {
                (0..DOF).all(|i| y[i] >= lower[i] - tol && y[i] <= upper[i] + tol)
                    && rows.iter().all(|(a, b)| a.dot(y) <= b + tol)
            };
            assert!(feasible(&x, 1e-6));
            let best = objective(&p, &c, &x);
            for _ in 0..2000 {
                let y = x + Vector7::from_fn(|_, _| rng.random_range(-1e-2..1e-2));
                if feasible(&y, 0.0) {
                    assert!(objective(&p, &c, &y) >= best - 1e-7, "a feasible point does better");
                }
            }
        }
    }

    /// Checks the KKT conditions of `solution` for ½xᵀPx − cᵀx, a·x ≤ b, independently of
    /// how it was found: feasible, multipliers nonnegative and zero off the constraints' edges,
    /// and Px − c + Σλa = 0, each to 1e-9 of the size of its terms.
    fn assert_kkt(p: &Matrix7, c: &Vector7, constraints: &dual::Constraints, s: &dual::Solution) {
        let x = s.x;
        let scale = 1.0 + x.amax();
        for k in 0..constraints.len() {
            let (a, b) = constraints.get(k);
            assert!(a.dot(&x) - b <= 1e-9 * (scale + b.abs()), "constraint {k} violated: {x}");
        }
        let mut gradient = p * x - c;
        for (k, lambda) in s.active.multipliers() {
            let (a, b) = constraints.get(k);
            assert!(lambda >= -1e-9, "multiplier {k} negative: {lambda}");
            let slack = (a.dot(&x) - b).abs();
            assert!(slack <= 1e-9 * (scale + b.abs()), "constraint {k} not tight: {slack}");
            gradient += a * lambda;
        }
        let size = (p.abs() * x.abs()).amax() + c.amax() + 1.0;
        assert!(gradient.amax() <= 1e-9 * size, "stationarity residual {}", gradient.amax());
    }

    /// Bounds cutting some joints of the unconstrained step, and rows cutting it off; one
    /// instance in eight made infeasible (a row against a box it cannot meet).
    fn random_instance(
        rng: &mut StdRng,
        exact: &Vector7,
    ) -> (Vector7, Vector7, Vec<(Vector7, Real)>) {
        // A joint speed limit's scale: a step QP's velocities are within a few rad/s.
        let mut upper = Vector7::repeat(10.0);
        let mut lower = Vector7::repeat(-10.0);
        let exact = &exact.map(|v| v.clamp(-10.0, 10.0));
        for _ in 0..rng.random_range(0..6) {
            let i = rng.random_range(0..DOF);
            let cut = rng.random_range(-0.5..0.9) * exact[i];
            if exact[i] > 0.0 { upper[i] = cut.max(lower[i]) } else { lower[i] = cut.min(upper[i]) }
        }
        let mut rows: Vec<(Vector7, Real)> = (0..rng.random_range(0..5))
            .map(|_| {
                let a = Vector7::from_fn(|_, _| rng.random_range(-1.0..1.0));
                let b = a.dot(exact) * rng.random_range(-0.5..1.0);
                (a, b)
            })
            .collect();
        if rng.random_range(0..8) == 0 {
            let box_ = Vector7::repeat(0.1);
            let (upper_, lower_) = (box_, -box_);
            upper = upper.inf(&upper_);
            lower = lower.sup(&lower_).inf(&upper);
            rows.push((Vector7::ith(0, 1.0) + Vector7::ith(1, 1.0), -1.0));
        }
        (lower, upper, rows)
    }

    #[test]
    fn the_dual_method_meets_the_kkt_conditions_and_agrees_with_clarabel() {
        let mut rng = StdRng::seed_from_u64(3);
        let mut solver = Clarabel::new(8).expect("set up");
        let (mut bound, mut infeasible) = (0, 0);
        for instance in 0..4000 {
            let (mut p, c) = random_problem(&mut rng);
            if instance % 4 == 0 {
                // A nearly singular J, as at the edge of a representation's validity.
                let (u, s, v) = {
                    let svd = p.svd(true, true);
                    (svd.u.expect("u"), svd.singular_values, svd.v_t.expect("v"))
                };
                let mut s = s;
                s[DOF - 1] = 1e-6;
                p = u * Matrix7::from_diagonal(&s) * v;
                p = 0.5 * (p + p.transpose());
            }
            let Some(ch) = p.cholesky() else { continue };
            let exact = ch.solve(&c);
            let (lower, upper, rows) = random_instance(&mut rng, &exact);
            let constraints = dual::Constraints { lower: &lower, upper: &upper, rows: &rows };
            let reference = solver.solve(&p, &c, &lower, &upper, &rows);
            match dual::solve(&ch, &c, &constraints) {
                dual::Outcome::Solved(s) => {
                    assert_kkt(&p, &c, &constraints, &s);
                    bound += usize::from(s.active.multipliers().count() > 0);
                    // Clarabel stops at its 1e-7 tolerances: the same optimum to those.
                    let (x, _) = reference.unwrap_or_else(|e| {
                        panic!(
                            "instance {instance}: Clarabel {e:?}; {lower} {upper} {rows:?} {}",
                            s.x
                        )
                    });
                    let (mine, theirs) = (objective(&p, &c, &s.x), objective(&p, &c, &x));
                    assert!(
                        (mine - theirs).abs() <= 1e-6 * (1.0 + theirs.abs()),
                        "{mine} {theirs}"
                    );
                }
                dual::Outcome::Infeasible => {
                    infeasible += 1;
                    assert!(
                        matches!(
                            reference,
                            Err(ClarabelFailure::Status(
                                ClarabelStatus::PrimalInfeasible
                                    | ClarabelStatus::AlmostPrimalInfeasible
                            ))
                        ),
                        "instance {instance}: Clarabel {reference:?}"
                    );
                }
                dual::Outcome::Degenerate => panic!("instance {instance}: degenerate"),
            }
        }
        // Most instances have binding constraints, some none can satisfy.
        assert!(bound > 2500 && infeasible > 300, "{bound} bound, {infeasible} infeasible");
    }

    #[test]
    fn with_nothing_violated_the_dual_answer_is_the_least_squares_step_bit_for_bit() {
        let mut rng = StdRng::seed_from_u64(4);
        for _ in 0..200 {
            let (p, c) = random_problem(&mut rng);
            let ch = p.cholesky().expect("positive definite");
            let exact = ch.solve(&c);
            let bound = Vector7::repeat(10.0 * exact.amax() + 1.0);
            let lower = -bound;
            let constraints = dual::Constraints { lower: &lower, upper: &bound, rows: &[] };
            let dual::Outcome::Solved(s) = dual::solve(&ch, &c, &constraints) else {
                panic!("solves")
            };
            assert_eq!(s.x, exact);
        }
    }

    /// COMAN's right arm and the start of the recorded-step tests: the elbow bent, the wrist
    /// in front of the shoulder.
    fn coman_bent_elbow() -> (Robot, JointVector) {
        let robot = Robot::from_urdf_file(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../robots/coman_right_arm.urdf"
        ))
        .expect("robot");
        let q0 = JointVector::from_fn(|i, _| [-10.0, -15.0, 45.0, -100.0, 0.0, 0.0, 0.0][i])
            .map(Real::to_radians);
        (robot, q0)
    }

    /// The QPs of real steps: COMAN's wrist along a line past a box close enough for damper
    /// rows, with slow joints so that bounds bind; each sample's step QP rebuilt by the
    /// controller and solved both ways.
    #[test]
    fn recorded_steps_are_solved_exactly() {
        use crate::kinematics::arm_pose;
        use crate::language::{Obstacle, PathFeature, Shape};
        use crate::math::{Rotation3, Vector3};
        use crate::profile::BodyFrames;

        let (robot, q0) = coman_bent_elbow();
        let pose0 = arm_pose(&robot, &q0);
        let s = cpsa_state(&robot, &pose0).expect("regular start");
        let duration = 1.2;
        let line =
            PathFeature::Line { direction: Vector3::new(0.0, -1.0, 0.2), length: Some(0.12) };
        let frames = BodyFrames { shoulder_frame: Rotation3::identity(), ow: s.ow };
        let held = |variable, value| Reference::hold(variable, value, duration).expect("hold");
        let pw = Reference::path(Variable::Pw, Target::Position(s.pw), &line, &frames, duration)
            .expect("line");
        let component = |variable, reference| Component { variable, reference, role: Role::Path };
        let problem = SegmentProblem {
            space: Space::Cpsa,
            components: [
                component(Variable::Pw, pw),
                component(Variable::Ow, held(Variable::Ow, Target::Rotation(s.ow))),
                component(Variable::Swivel, held(Variable::Swivel, Target::Angle(s.swivel))),
            ],
            duration,
        };
        let slab = Obstacle {
            name: "slab".into(),
            shape: Shape::Box {
                center: pose0.wrist + Vector3::new(0.0, -0.08, -0.07),
                size: Vector3::new(0.3, 0.1, 0.05),
                rotation: Rotation3::identity(),
            },
        };
        let scene = CollisionScene::new(&[slab]);
        let options = QpOptions { velocity_fraction: 0.3, ..QpOptions::default() };
        let solved = solve_segment(&robot, &scene, &problem, &q0, &options).expect("solves");
        let mut controller = Controller::new(&robot, &scene, problem, &options);
        let mut clarabel = Clarabel::new(8).expect("set up");
        let (mut binding, mut rows_seen, mut infeasible) = (0, 0, 0);
        let tr = &solved.trajectory;
        for k in 0..tr.len() {
            let (q, current, t) = (tr.positions()[k], tr.velocities()[k], tr.times()[k]);
            let pose = arm_pose(&robot, &q);
            let (jacobian, values) = controller.measure(&pose).expect("regular");
            let (target, weights, _) = controller.task(t, &values);
            let weighted = Matrix7::from_diagonal(&weights.component_mul(&weights)) * jacobian;
            let p = jacobian.transpose() * weighted + Matrix7::identity() * 1e-6;
            let c = weighted.transpose() * target;
            let (lower, upper) = controller.bounds(&q);
            let (ramp_lower, ramp_upper) = controller.ramp(&lower, &upper, &current);
            let rows = controller.damper_rows(&pose, &q);
            rows_seen += usize::from(!rows.is_empty());
            let constraints =
                dual::Constraints { lower: &ramp_lower, upper: &ramp_upper, rows: &rows };
            let ch = p.cholesky().expect("positive definite");
            let mut outcome = dual::solve(&ch, &c, &constraints);
            let mut constraints = constraints;
            if matches!(outcome, dual::Outcome::Infeasible) {
                // As the controller does: Clarabel confirms it, and the rows are kept within
                // the velocity box.
                infeasible += 1;
                let reference = clarabel.solve(&p, &c, &ramp_lower, &ramp_upper, &rows);
                assert!(
                    matches!(
                        reference,
                        Err(ClarabelFailure::Status(ClarabelStatus::PrimalInfeasible))
                    ),
                    "step {k}: Clarabel {reference:?}"
                );
                constraints = dual::Constraints { lower: &lower, upper: &upper, rows: &rows };
                outcome = dual::solve(&ch, &c, &constraints);
            }
            let dual::Outcome::Solved(s) = outcome else { panic!("step {k}: {outcome:?}") };
            assert_kkt(&p, &c, &constraints, &s);
            if s.active.multipliers().count() > 0 {
                binding += 1;
                let (x, _) = clarabel
                    .solve(&p, &c, constraints.lower, constraints.upper, &rows)
                    .expect("Clarabel solves it");
                let (mine, theirs) = (objective(&p, &c, &s.x), objective(&p, &c, &x));
                assert!((mine - theirs).abs() <= 1e-6 * (1.0 + theirs.abs()), "{mine} {theirs}");
            }
            controller.clarabel = None;
        }
        assert!(binding > 50 && rows_seen > 50, "{binding} binding, {rows_seen} with rows");
        eprintln!(
            "{} steps: {binding} binding, {rows_seen} with rows, {infeasible} infeasible",
            tr.len()
        );
    }

    /// [`Controller::damper_rows`] from parry's closest points of every pair
    /// ([`collision::distances`]): the independent reference.
    fn parry_damper_rows(
        robot: &Robot,
        scene: &CollisionScene,
        options: &QpOptions,
        pose: &ArmPose,
    ) -> Vec<(Vector7, Real)> {
        let influence = collision::DistanceOptions { influence: options.influence };
        let near = collision::distances(robot, pose, scene, &influence);
        near.iter()
            .map(|p| {
                let link = point_jacobian(pose, p.link_frame, &p.on_link);
                let relative = match p.obstacle_frame {
                    Some(frame) => link - point_jacobian(pose, frame, &p.on_obstacle),
                    None => link,
                };
                damper_row(options, &p.normal, &relative, p.distance)
            })
            .collect()
    }

    /// The closed-form rows are parry's ([`collision::distances`]' closest points) at every
    /// configuration: the same pairs in the same order, each row within what parry's GJK may
    /// be off by, except a pair that parry and the closed form put on either side of the
    /// influence distance, whose row allows the approach at ξ and binds nothing.
    #[test]
    fn damper_rows_are_parrys_rows() {
        use crate::kinematics::arm_pose;
        use crate::language::{Obstacle, Shape};
        use crate::math::{Rotation3, Vector3};

        let (robot, q0) = coman_bent_elbow();
        let wrist = arm_pose(&robot, &q0).wrist;
        let obstacles = [
            Obstacle {
                name: "slab".into(),
                shape: Shape::Box {
                    center: wrist + Vector3::new(0.0, -0.08, -0.09),
                    size: Vector3::new(0.3, 0.1, 0.05),
                    rotation: Rotation3::from_euler_angles(0.3, 0.1, 0.0),
                },
            },
            Obstacle {
                name: "post".into(),
                shape: Shape::Cylinder {
                    center: wrist + Vector3::new(0.1, 0.05, 0.0),
                    radius: 0.03,
                    height: 0.4,
                    rotation: Rotation3::identity(),
                },
            },
        ];
        let scene = CollisionScene::new(&obstacles);
        let problem = SegmentProblem {
            space: Space::Cpsa,
            components: std::array::from_fn(|k| {
                let variable = [Variable::Pw, Variable::Ow, Variable::Swivel][k];
                let value = [
                    Target::Position(wrist),
                    Target::Rotation(Rotation3::identity()),
                    Target::Angle(0.0),
                ][k];
                let reference = Reference::hold(variable, value, 1.0).expect("hold");
                Component { variable, reference, role: Role::Path }
            }),
            duration: 1.0,
        };
        let options = QpOptions::default();
        let controller = Controller::new(&robot, &scene, problem, &options);
        let mut rng = StdRng::seed_from_u64(5);
        let (mut with_rows, mut without, mut closest, mut worst) = (0, 0, 0, 0.0_f64);
        for _ in 0..3000 {
            let q = q0 + JointVector::from_fn(|_, _| rng.random_range(-1.5..1.5));
            let pose = arm_pose(&robot, &q);
            let rows = controller.damper_rows(&pose, &q);
            let parrys = parry_damper_rows(&robot, &scene, &options, &pose);
            // The influence distance's row: b = ξ, a anything.
            let edge = |(_, b): &&(Vector7, Real)| (b - options.damper_speed).abs() < 1e-3;
            let (mine, theirs): (Vec<_>, Vec<_>) = if rows.len() == parrys.len() {
                (rows.iter().collect(), parrys.iter().collect())
            } else {
                (
                    rows.iter().filter(|r| !edge(r)).collect(),
                    parrys.iter().filter(|r| !edge(r)).collect(),
                )
            };
            assert_eq!(mine.len(), theirs.len(), "at {q}: {rows:?} against {parrys:?}");
            for ((a, b), (a_parry, b_parry)) in mine.iter().zip(&theirs) {
                // parry's distance is up to MEASURE_SLACK off. A segment nearly parallel to a
                // face is nearly as close all along it: parry and the closed form may take
                // points apart on it, and the rows' Jacobians differ by as much.
                let slack = collision::MEASURE_SLACK;
                let b_scale = options.damper_speed / (options.influence - options.safety_distance);
                assert!((b - b_parry).abs() <= b_scale * slack, "at {q}: {b} against {b_parry}");
                worst = worst.max((a - a_parry).norm() / a_parry.norm().max(1.0));
                assert!(
                    (a - a_parry).norm() <= 1e-2 * a_parry.norm().max(1.0),
                    "at {q}: {a} against {a_parry}"
                );
            }
            closest += rows
                .iter()
                .zip(&parrys)
                .filter(|((a, _), (ap, _))| (a - ap).norm() <= 1e-6)
                .count();
            if rows.is_empty() { without += 1 } else { with_rows += 1 }
        }
        assert!(with_rows > 200 && without > 200, "{with_rows} with rows, {without} without");
        eprintln!("{closest} rows within 1e-6 of parry's; worst a {worst:e}");
    }

    #[test]
    fn options_out_of_range_are_refused() {
        let bad = [
            QpOptions { gain: 600.0, ..QpOptions::default() },
            QpOptions { influence: 0.005, ..QpOptions::default() },
            QpOptions { velocity_fraction: 1.5, ..QpOptions::default() },
            QpOptions { rest_speed: 0.0, ..QpOptions::default() },
        ];
        for o in bad {
            assert!(matches!(check_options(&o), Err(QpError::InvalidOptions { .. })), "{o:?}");
        }
        assert!(check_options(&QpOptions::default()).is_ok());
    }
}
