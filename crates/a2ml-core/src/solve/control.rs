//! The velocity-level control loop every resolver-based solver shares: measure, reference,
//! step, integrate, settle, stall, brake.
//!
//! A [`Resolver`] maps the arm's configuration, its velocity and the segment time to a joint
//! velocity q' (its formula: the velocity QP's step, a baseline's pseudo-inverse) and says how
//! far its task is from done; [`run`] integrates it on a fixed grid (trapezoidal, explicit
//! Euler or RK4), runs past the segment's duration until the task is reached and the arm at
//! rest, stops when progress stalls, and brakes to rest when it stops while moving (the
//! resolver holding where it stopped, or q' decaying), so the next action starts from rest.
//! The hand references the baselines follow ([`HandReference`]) are built here from a
//! segment.

use std::time::Instant;

use nalgebra::SVector;

use super::clik::ClikOptions;
use super::gpm::GpmOptions;
use super::monitor::Monitor;
use super::pmp::PmpOptions;
use super::problem::SegmentProblem;
use super::report::Tolerance;
use crate::decompose::ArmState;
use crate::kinematics::{ArmPose, arm_pose};
use crate::language::Target;
use crate::math::{JointVector, Real, Rotation3, Vector3, rotation_log};
use crate::profile::{PositionReference, ProfileError, Reference, RotationReference};
use crate::robot::Robot;
use crate::trajectory::{Trajectory, TrajectoryError};

/// A 6-vector: a hand twist [v; ω] or a pose error [e_p; e_R].
pub type Vector6 = SVector<Real, 6>;

/// How the loop integrates q' over a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Integration {
    /// The velocity ramps linearly over the step from the arm's velocity to the resolver's
    /// answer, q ← q + h (q'₀ + q')/2: one resolver call per step, and the samples (q and
    /// the velocity at the step's start) are one piecewise-quadratic motion. The QP's, whose
    /// answer is bounded by the acceleration limits around the velocity the arm has.
    Trapezoid,
    /// q ← q + h q'(q, t): one resolver call per step.
    Euler,
    /// Classical Runge-Kutta: four calls per step, O(h⁴), so that a resolver that tracks its
    /// task exactly in continuous time does so on the grid to far below a micrometre.
    Rk4,
}

/// Settings of the control loop.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ControlOptions {
    /// Control step h (s), default 2 ms.
    pub step: Real,
    /// The integration scheme, default RK4.
    pub integration: Integration,
    /// Longest time run past the segment's duration to settle (s), default 1.
    pub max_settle: Real,
    /// Joint speed under which the arm counts as at rest (rad/s), default 5e-4.
    pub rest_speed: Real,
    /// Window over which progress is measured while settling (s), default 0.2.
    pub stall_window: Real,
    /// Settling stalls when the error falls by less than this fraction over the window,
    /// default 0.01.
    pub stall_fraction: Real,
    /// Rate (1/s) at which q' decays to rest after the loop stopped while moving, default 20.
    pub brake_rate: Real,
    /// Time (s) over which q' is faded in from rest at the start, ½(1 - cos(π t/ramp)),
    /// default 0: the resolver's formula as it is. Velocity-level formulas with a null-space
    /// or elastic term command a velocity at t = 0, which a sequential join (+Se) refuses.
    pub start_ramp: Real,
    /// When a resolver's task counts as reached.
    pub tolerance: Tolerance,
}

impl Default for ControlOptions {
    fn default() -> Self {
        Self {
            step: 0.002,
            integration: Integration::Rk4,
            max_settle: 1.0,
            rest_speed: 5e-4,
            stall_window: 0.2,
            stall_fraction: 0.01,
            brake_rate: 20.0,
            start_ramp: 0.0,
            tolerance: Tolerance::default(),
        }
    }
}

/// The settings of the three baselines and their loop, one field of
/// [`super::PlanOptions`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BaselineOptions {
    /// The control loop (its tolerance is replaced by the plan's); by default its
    /// `start_ramp` is 0.1 s, so that every segment starts from rest as the actions' +Se
    /// joins need.
    pub control: ControlOptions,
    /// The gradient projection method.
    pub gpm: GpmOptions,
    /// The weighted CLIK with virtual end-effectors.
    pub clik: ClikOptions,
    /// λ0-PMP and its variants.
    pub pmp: PmpOptions,
}

impl Default for BaselineOptions {
    fn default() -> Self {
        Self {
            control: ControlOptions { start_ramp: 0.1, ..ControlOptions::default() },
            gpm: GpmOptions::default(),
            clik: ClikOptions::default(),
            pmp: PmpOptions::default(),
        }
    }
}

/// Why a resolver-based segment cannot be solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControlError {
    /// The settings are out of range.
    #[error("invalid settings: {reason}")]
    InvalidOptions {
        /// What is wrong.
        reason: &'static str,
    },
    /// The wall-clock limit set by the user passed.
    #[error("timeout at t = {time:.3} s: the time limit passed")]
    Timeout {
        /// Segment time (s).
        time: Real,
    },
    /// The resolver's task Jacobian lost rank where the arm is.
    #[error("at t = {time:.3} s the {what} is singular")]
    Singular {
        /// Segment time (s).
        time: Real,
        /// Which matrix.
        what: &'static str,
    },
    /// The segment's goal gives no hand pose (its state has no CPSA form).
    #[error("the segment's goal has no hand pose: {reason}")]
    NoHandGoal {
        /// Why.
        reason: String,
    },
    /// A hand reference cannot be built.
    #[error(transparent)]
    Reference(#[from] ProfileError),
    /// The samples do not make a trajectory (a resolver diverged).
    #[error(transparent)]
    Trajectory(#[from] TrajectoryError),
}

/// What a resolver returns at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resolved {
    /// The joint velocity q' (rad/s).
    pub velocity: JointVector,
    /// The resolver's task error in units of its tolerance (the largest over its
    /// components): ≤ 1 is reached. The loop settles and detects stalls on it.
    pub error: Real,
}

/// A velocity-level solver: the formula that maps the arm's configuration to q'.
///
/// A resolver holds its robot, its references and any state of its own (CLIK's layers, PMP's
/// clock, the QP's solver); the loop owns q, the arm's velocity and time. It may be called at
/// any t ≥ 0 within a step (RK4 calls it at t, t + h/2 and t + h), and past the segment's
/// duration while the loop settles.
pub trait Resolver {
    /// What a resolver's step can fail with; the loop's own errors convert into it.
    type Error: From<ControlError>;

    /// q' at configuration `q` (FK already done: `pose`), where the arm moves at `velocity`,
    /// at segment time `t`, with the task error there.
    ///
    /// # Errors
    /// Where its formula has no answer (for the baselines [`ControlError::Singular`], where
    /// an inverse does not exist).
    fn resolve(
        &mut self,
        pose: &ArmPose,
        q: &JointVector,
        velocity: &JointVector,
        t: Real,
    ) -> Result<Resolved, Self::Error>;

    /// An upper bound of the closed loop's fastest rate (1/s) near `pose`, for RK4's
    /// substeps; 0 (the default) when the control step is always small enough.
    fn fastest_rate(&self, pose: &ArmPose) -> Real {
        let _ = pose;
        0.0
    }

    /// The number whose fall the loop watches while settling, to tell a stall (by default
    /// the task error of `resolved`).
    fn progress(&self, resolved: &Resolved) -> Real {
        resolved.error
    }

    /// Switches the resolver to holding the state at `pose`, where the loop stopped while the
    /// arm moves at `velocity`, on a grid of `step` (s); then the loop runs it, from time 0,
    /// for at most the steps returned or until the arm is at rest. `None` (the default): the
    /// loop brakes on its own, q' decaying at [`ControlOptions::brake_rate`].
    ///
    /// # Errors
    /// When the state cannot be held.
    fn hold(
        &mut self,
        pose: &ArmPose,
        velocity: &JointVector,
        step: Real,
    ) -> Result<Option<usize>, Self::Error> {
        let _ = (pose, velocity, step);
        Ok(None)
    }
}

/// A segment run through the loop.
#[derive(Debug, Clone, PartialEq)]
pub struct ControlRun {
    /// Every step: time from 0 (s), q, q' (the resolver's at that sample).
    pub trajectory: Trajectory,
    /// Time run past the duration to settle and brake (s).
    pub settle: Real,
    /// The resolver's task within tolerance at the end.
    pub reached: bool,
    /// Settling stopped making progress short of the task.
    pub stalled: bool,
    /// Control steps taken (braking excluded).
    pub steps: usize,
    /// Mean wall time of a step, all its resolver calls included (s).
    pub mean_step_time: Real,
}

fn check_options(o: &ControlOptions) -> Result<(), ControlError> {
    let positive = |x: Real| x.is_finite() && x > 0.0;
    let checks = [
        (positive(o.step), "the step must be positive"),
        (o.max_settle.is_finite() && o.max_settle >= 0.0, "negative settle time"),
        (positive(o.rest_speed), "the rest speed must be positive"),
        (positive(o.stall_window), "the stall window must be positive"),
        (positive(o.stall_fraction) && o.stall_fraction < 1.0, "stall fraction out of (0, 1)"),
        (positive(o.brake_rate) && o.brake_rate * o.step < 1.0, "brake rate out of range"),
        (o.start_ramp.is_finite() && o.start_ramp >= 0.0, "negative start ramp"),
    ];
    match checks.iter().find(|(ok, _)| !ok) {
        Some((_, reason)) => Err(ControlError::InvalidOptions { reason }),
        None => Ok(()),
    }
}

/// Integrates `resolver` from `q0` over a segment of `duration` (s), then settles and brakes.
///
/// Steps land exactly on the duration; settling continues on the same grid until the task is
/// reached with the arm at rest, its progress stalls, or `max_settle` runs out. A run that
/// stops while moving brakes until at rest: the resolver holds the state it reached
/// ([`Resolver::hold`]), or q' decays at `brake_rate`.
///
/// # Errors
/// [`ControlError`] (as the resolver's error): invalid settings, a resolver error, or
/// non-finite samples.
pub fn run<R: Resolver>(
    robot: &Robot,
    resolver: &mut R,
    q0: &JointVector,
    duration: Real,
    options: &ControlOptions,
) -> Result<ControlRun, R::Error> {
    run_monitored(robot, resolver, q0, duration, options, &mut Monitor::silent())
}

/// Control steps between two progress reports and deadline checks.
const REPORT_EVERY: usize = 64;

/// [`run`], reporting the fraction of the duration done to `monitor` and stopping at its
/// deadline ([`ControlError::Timeout`]).
///
/// # Errors
/// As [`run`].
pub fn run_monitored<R: Resolver>(
    robot: &Robot,
    resolver: &mut R,
    q0: &JointVector,
    duration: Real,
    options: &ControlOptions,
    monitor: &mut Monitor,
) -> Result<ControlRun, R::Error> {
    check_options(options)?;
    if !(duration.is_finite() && duration > 0.0) {
        return Err(ControlError::InvalidOptions { reason: "the duration must be positive" }.into());
    }
    let steps = (duration / options.step).ceil().max(1.0) as usize;
    let h = duration / steps as Real;
    let settle_steps = (options.max_settle / h).ceil() as usize;
    let window = ((options.stall_window / h).ceil() as usize).max(1);
    let ramp = options.start_ramp;
    let call = |resolver: &mut R, q: &JointVector, velocity: &JointVector, t: Real| {
        let mut resolved = resolver.resolve(&arm_pose(robot, q), q, velocity, t)?;
        if t < ramp {
            resolved.velocity *= 0.5 * (1.0 - (std::f64::consts::PI * t / ramp).cos());
        }
        Ok::<Resolved, R::Error>(resolved)
    };

    let (mut times, mut positions, mut velocities) = (Vec::new(), Vec::new(), Vec::new());
    let mut progress: Vec<Real> = Vec::new();
    let mut q = *q0;
    // The arm's velocity at the step's start; each segment starts at rest.
    let mut velocity = JointVector::zeros();
    let mut k = 0;
    let mut wall = 0.0;
    let (reached, stalled) = loop {
        let started = Instant::now();
        let t = k as Real * h;
        if k % REPORT_EVERY == 0 {
            if monitor.expired() {
                return Err(ControlError::Timeout { time: t }.into());
            }
            monitor.report(t / duration.max(h));
        }
        let now = call(resolver, &q, &velocity, t)?;
        if options.integration != Integration::Trapezoid {
            velocity = now.velocity;
        }
        times.push(t);
        positions.push(q);
        velocities.push(velocity);
        if k >= steps {
            let reached = now.error <= 1.0;
            let at_rest = velocity.amax().max(now.velocity.amax()) <= options.rest_speed;
            let score = resolver.progress(&now);
            progress.push(score);
            let n = progress.len();
            let stuck =
                n > window && progress[n - 1 - window] - score <= options.stall_fraction * score;
            if (reached && at_rest) || stuck || k >= steps + settle_steps {
                wall += started.elapsed().as_secs_f64();
                break (reached, !reached && stuck);
            }
        }
        q = match options.integration {
            Integration::Trapezoid => q + (velocity + now.velocity) * (0.5 * h),
            Integration::Euler => q + now.velocity * h,
            Integration::Rk4 => {
                // Substeps keep RK4 inside its stability region (|rate · step| ≤ 1 < 2.78).
                let rate = resolver.fastest_rate(&arm_pose(robot, &q));
                let n = (rate * h).ceil().clamp(1.0, 1e4) as usize;
                let d = h / n as Real;
                let mut p = q;
                for i in 0..n {
                    let s = t + i as Real * d;
                    let v = velocity;
                    let k1 =
                        if i == 0 { now.velocity } else { call(resolver, &p, &v, s)?.velocity };
                    let k2 = call(resolver, &(p + k1 * (d / 2.0)), &v, s + d / 2.0)?.velocity;
                    let k3 = call(resolver, &(p + k2 * (d / 2.0)), &v, s + d / 2.0)?.velocity;
                    let k4 = call(resolver, &(p + k3 * d), &v, s + d)?.velocity;
                    p += (k1 + (k2 + k3) * 2.0 + k4) * (d / 6.0);
                }
                p
            }
        };
        velocity = now.velocity;
        if q.iter().any(|x| !x.is_finite()) {
            let error = TrajectoryError::NonFinite { what: "position", sample: k + 1 };
            return Err(ControlError::from(error).into());
        }
        wall += started.elapsed().as_secs_f64();
        k += 1;
    };
    let taken = times.len();
    if velocity.amax() > options.rest_speed {
        match resolver.hold(&arm_pose(robot, &q), &velocity, h)? {
            Some(most) => {
                // The resolver holds the state reached: its own steps bring the arm to rest.
                let start = *times.last().unwrap_or(&0.0);
                let mut t = start;
                for _ in 0..most {
                    let now = call(resolver, &q, &velocity, t - start)?;
                    q = match options.integration {
                        Integration::Trapezoid => q + (velocity + now.velocity) * (0.5 * h),
                        _ => q + now.velocity * h,
                    };
                    velocity = now.velocity;
                    t += h;
                    times.push(t);
                    positions.push(q);
                    velocities.push(velocity);
                    if velocity.amax() <= options.rest_speed {
                        break;
                    }
                }
            }
            None => brake(&mut times, &mut positions, &mut velocities, h, options),
        }
    }
    let trajectory = Trajectory::new(times, positions, velocities).map_err(ControlError::from)?;
    Ok(ControlRun {
        settle: (trajectory.duration() - duration).max(0.0),
        trajectory,
        reached,
        stalled,
        steps: taken,
        mean_step_time: wall / taken as Real,
    })
}

/// Brings a run that stopped while moving to rest: q' decays exponentially, q follows it
/// exactly (the arm coasts |q'|/rate further), so the samples stay consistent.
fn brake(
    times: &mut Vec<Real>,
    positions: &mut Vec<JointVector>,
    velocities: &mut Vec<JointVector>,
    h: Real,
    options: &ControlOptions,
) {
    let (Some(&t0), Some(&q0), Some(&v0)) = (times.last(), positions.last(), velocities.last())
    else {
        return;
    };
    let rate = options.brake_rate;
    let mut t = 0.0;
    while v0.amax() * (-rate * t).exp() > options.rest_speed {
        t += h;
        let decay = (-rate * t).exp();
        times.push(t0 + t);
        positions.push(q0 + v0 * ((1.0 - decay) / rate));
        velocities.push(v0 * decay);
    }
    if let Some(last) = velocities.last_mut() {
        if t > 0.0 {
            *last = JointVector::zeros();
        }
    }
}

/// A hand pose reference: Pw and Ow over a segment, each with its velocity in {b}.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HandReference {
    /// Pw (m).
    pub position: PositionReference,
    /// Ow.
    pub rotation: RotationReference,
}

/// A hand reference at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HandSample {
    /// Pw (m).
    pub position: Vector3,
    /// Pw' (m/s).
    pub velocity: Vector3,
    /// Ow.
    pub rotation: Rotation3,
    /// ω of Ow (rad/s, in {b}).
    pub angular_velocity: Vector3,
}

impl HandReference {
    /// The straight wrist line and the geodesic rotation from (`pw`, `ow`) to the goal, both
    /// with the bell profile over `duration` (A2ML eq. 15's X_d).
    ///
    /// # Errors
    /// Non-finite inputs or an invalid duration.
    pub fn straight(
        start: (Vector3, Rotation3),
        goal: (Vector3, Rotation3),
        duration: Real,
    ) -> Result<Self, ProfileError> {
        Ok(Self {
            position: PositionReference::goal(start.0, goal.0, duration)?,
            rotation: RotationReference::goal(start.1, goal.1, duration)?,
        })
    }

    /// The segment's own hand path: in CPSA its Pw and Ow references (lines, arcs and holds
    /// as written), in HAT the straight one from `start` to [`hand_goal`].
    ///
    /// # Errors
    /// [`ControlError::NoHandGoal`] when a HAT goal has no CPSA form.
    pub fn of_segment(
        robot: &Robot,
        problem: &SegmentProblem,
        start: (Vector3, Rotation3),
    ) -> Result<Self, ControlError> {
        if let [Reference::Position(position), Reference::Rotation(rotation), _] =
            problem.components.map(|c| c.reference)
        {
            return Ok(Self { position, rotation });
        }
        Ok(Self::straight(start, hand_goal(robot, problem)?, problem.duration)?)
    }

    /// Pw, Ow and their velocities at t, clamped to the reference's duration.
    pub fn sample(&self, t: Real) -> HandSample {
        let (position, velocity) = self.position.sample(t);
        let (rotation, angular_velocity) = self.rotation.sample(t);
        HandSample { position, velocity, rotation, angular_velocity }
    }
}

/// The hand pose (Pw, Ow) at the end of a segment's references: read off in CPSA, mapped
/// from (Os, θe, Ow) in HAT.
///
/// # Errors
/// [`ControlError::NoHandGoal`] when the end state has no CPSA form.
pub fn hand_goal(
    robot: &Robot,
    problem: &SegmentProblem,
) -> Result<(Vector3, Rotation3), ControlError> {
    let ends: [Target; 3] = problem.components.map(|c| c.reference.end());
    let state = ArmState::from_space(robot, problem.space, &ends).ok_or_else(|| {
        ControlError::NoHandGoal { reason: "the end state is outside the arm's reach".into() }
    })?;
    Ok((state.cpsa.pw, state.cpsa.ow))
}

/// The hand's pose error [Pw_d - Pw; log(R_d Rᵀ)] (m, rad; in {b}).
pub fn pose_error(pose: &ArmPose, position: &Vector3, rotation: &Rotation3) -> Vector6 {
    let mut e = Vector6::zeros();
    e.fixed_rows_mut::<3>(0).copy_from(&(position - pose.wrist));
    e.fixed_rows_mut::<3>(3).copy_from(&rotation_log(&(rotation * pose.hand.inverse())));
    e
}

/// A pose error in units of the tolerance: the larger of position/tolerance and
/// angle/tolerance.
pub fn pose_error_score(error: &Vector6, tolerance: &Tolerance) -> Real {
    let position = error.fixed_rows::<3>(0).norm() / tolerance.position;
    let angle = error.fixed_rows::<3>(3).norm() / tolerance.angle;
    position.max(angle)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// q' = -a (q - q_goal): the loop must settle at rest on the goal, at rate a.
    struct Decay {
        goal: JointVector,
        rate: Real,
    }

    impl Resolver for Decay {
        type Error = ControlError;

        fn resolve(
            &mut self,
            _: &ArmPose,
            q: &JointVector,
            _: &JointVector,
            _: Real,
        ) -> Result<Resolved, ControlError> {
            let e = self.goal - q;
            Ok(Resolved { velocity: e * self.rate, error: e.amax() / 1e-6 })
        }
    }

    fn robot() -> Robot {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/iiwa14.urdf");
        Robot::from_urdf_file(path).expect("robot loads")
    }

    #[test]
    fn rk4_follows_an_exponential_to_fourth_order_and_settles_at_rest() {
        let robot = robot();
        let goal = JointVector::repeat(0.3);
        let mut decay = Decay { goal, rate: 5.0 };
        let options = ControlOptions { max_settle: 5.0, ..ControlOptions::default() };
        let run = run(&robot, &mut decay, &JointVector::zeros(), 0.5, &options).expect("runs");
        let at = |i: usize| run.trajectory.positions()[i][0];
        // q(t) = 0.3 (1 - e^{-5t}) at the grid's t = 0.5 s (sample 250).
        let exact = 0.3 * (1.0 - (-2.5_f64).exp());
        assert!((at(250) - exact).abs() < 1e-10, "{} vs {exact}", at(250));
        assert!(run.reached && !run.stalled);
        let last = run.trajectory.velocities().last().expect("samples");
        assert!(last.amax() <= options.rest_speed);
    }

    #[test]
    fn a_run_cut_short_while_moving_brakes_to_rest_consistently() {
        let robot = robot();
        let mut decay = Decay { goal: JointVector::repeat(1.0), rate: 0.5 };
        let options = ControlOptions { max_settle: 0.0, ..ControlOptions::default() };
        let run = run(&robot, &mut decay, &JointVector::zeros(), 0.2, &options).expect("runs");
        assert!(!run.reached);
        let t = &run.trajectory;
        assert_eq!(t.velocities().last().map(|v| v.amax()), Some(0.0));
        // Coasting: positions are the integral of the decaying velocity.
        let n = t.len();
        let (q1, q2) = (t.positions()[n - 2][0], t.positions()[n - 3][0]);
        let (v1, v2) = (t.velocities()[n - 2][0], t.velocities()[n - 3][0]);
        let h = t.times()[n - 2] - t.times()[n - 3];
        assert!((q1 - q2 - 0.5 * (v1 + v2) * h).abs() < 1e-3 * v2.abs() * h + 1e-15);
    }

    #[test]
    fn bad_options_are_refused() {
        for o in [
            ControlOptions { step: 0.0, ..ControlOptions::default() },
            ControlOptions { brake_rate: 1e4, ..ControlOptions::default() },
            ControlOptions { stall_fraction: 1.0, ..ControlOptions::default() },
        ] {
            assert!(matches!(check_options(&o), Err(ControlError::InvalidOptions { .. })));
        }
    }
}
