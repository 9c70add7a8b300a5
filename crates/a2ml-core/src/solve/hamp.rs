//! The HAMP planner for handovers (Zhao, Wang & Xie; METHODS.md §3.4-3.5): from a start
//! configuration to a target hand pose, P on a straight minimum-jerk line timed by Fitts'
//! law, O on a cosine bell about a fixed axis over the same time, and Φ on one cosine bell
//! whose window is placed by the chosen pattern per phase and the duration ratios R_Φ; the
//! joints follow by CPSA IK at every sample, their velocities by J_cs⁻¹.
//!
//! Entry point: [`plan_handover`]. P is the wrist centre Pw (the paper uses the fingertip).

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use crate::collision::CollisionScene;
use crate::decompose::FittsLaw;
use crate::kinematics::{
    CpsaState, KinematicsError, arm_pose, cpsa_jacobian, cpsa_state, ik_cpsa, swivel_intervals,
};
use crate::math::{JointVector, Real, Rotation3, Vector3, Vector7, rotation_about, rotation_log};
use crate::metrics::pattern::{Hamp, Primitive};
use crate::robot::Robot;
use crate::trajectory::{
    Clearance, LimitViolation, Trajectory, TrajectoryError, check_limits, min_clearance,
    sample_times,
};

/// Which handover motion: the patterns are chosen differently for each (paper §5.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Handover {
    /// Reaching to take an object: phase 1 ΦPO, phase 2 ΦPO-PO.
    #[default]
    PickUp,
    /// Bringing it to the receiver: patterns chosen by the ratio R_d.
    Delivery,
}

/// Where the hand goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HandoverTarget {
    /// Pw at the end (m, {b}).
    pub pw: Vector3,
    /// Ow at the end.
    pub ow: Rotation3,
    /// θsw at the end (rad); `None`: the middle of the widest joint-limit-feasible swivel
    /// interval at the target (the paper's static posture model is not described).
    pub swivel: Option<Real>,
}

/// Settings of the HAMP planner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HampOptions {
    /// Pick-up or delivery.
    pub handover: Handover,
    /// Seed of the draws of R_Φ within its band (the paper draws them at random).
    pub seed: u64,
    /// Sample rate of the trajectory (Hz); the paper's data are at 120 Hz.
    pub rate: Real,
    /// Fitts' law for the duration.
    pub fitts: FittsLaw,
}

impl Default for HampOptions {
    fn default() -> Self {
        Self { handover: Handover::PickUp, seed: 0, rate: 120.0, fitts: FittsLaw::default() }
    }
}

/// Why a handover cannot be planned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HampError {
    /// The sample rate is not positive and finite.
    #[error("invalid sample rate {rate} Hz: it must be positive and finite")]
    InvalidRate {
        /// The rate asked for (Hz).
        rate: Real,
    },
    /// The start configuration has no CPSA state.
    #[error("the start configuration: {0}")]
    Start(KinematicsError),
    /// No goal swivel was given and none can be chosen at the target.
    #[error("the target: no swivel angle within the joint limits: {0}")]
    Target(KinematicsError),
    /// The hand does not move: a handover needs a distance to time by Fitts' law.
    #[error("the target is where the wrist already is: nothing to hand over")]
    NoTravel,
    /// A sample of the planned CPSA path has no IK solution within the joint limits.
    #[error("at t = {time:.3} s: {source}")]
    Ik {
        /// Time of the sample (s).
        time: Real,
        /// Why.
        source: KinematicsError,
    },
    /// IK jumped to another branch between two samples.
    #[error("at t = {time:.3} s the joints jump by {jump:.3} rad (IK changed branch)")]
    Discontinuous {
        /// Time of the sample (s).
        time: Real,
        /// Largest joint change from the previous sample (rad).
        jump: Real,
    },
    /// J_cs is singular at a sample, so the joint velocities are undefined.
    #[error("at t = {time:.3} s J_cs is singular")]
    SingularJacobian {
        /// Time of the sample (s).
        time: Real,
    },
    /// The samples do not make a trajectory.
    #[error(transparent)]
    Trajectory(#[from] TrajectoryError),
}

/// A planned handover: the trajectory, the patterns it was planned with and its timing.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HampPlan {
    /// q and q' at `rate`, from 0 to `duration`.
    pub trajectory: Trajectory,
    /// The pattern of phase 1 (up to P's speed peak).
    pub phase1: Hamp,
    /// The pattern of phase 2.
    pub phase2: Hamp,
    /// T from Fitts' law for the wrist's travel (s).
    pub duration: Real,
    /// T1, the time of P's speed peak (s).
    pub peak_time: Real,
    /// The wrist's travel ΔP (m).
    pub travel: Real,
    /// Φ at the start and at the end (rad).
    pub swivel: (Real, Real),
    /// When Φ moves: its bell's start and end (s); `None` when Φ does not change.
    pub swivel_window: Option<(Real, Real)>,
    /// R_Φ1 and R_Φ2: the shares of phases 1 and 2 in which Φ moves.
    pub swivel_ratios: (Real, Real),
    /// R_d = (ΔΦ/Φ_M) / (ΔP/P_M), with Φ_M the feasible swivel width at the target (π when
    /// unknown) and P_M = lu + lf.
    pub duration_ratio: Real,
    /// Every joint position or speed limit exceeded (none: IK keeps the positions inside).
    pub limit_violations: Vec<LimitViolation>,
    /// The smallest clearance to the scene and between the arm's own links.
    pub clearance: Option<Clearance>,
}

/// s(τ) and s'(τ) of the minimum-jerk profile (paper eq. 13): 10τ³ - 15τ⁴ + 6τ⁵.
fn minimum_jerk(tau: Real) -> (Real, Real) {
    let t = tau.clamp(0.0, 1.0);
    let s = t * t * t * (10.0 - 15.0 * t + 6.0 * t * t);
    let ds = 30.0 * t * t * (1.0 - t) * (1.0 - t);
    (s, if (0.0..=1.0).contains(&tau) { ds } else { 0.0 })
}

/// s(t) and s'(t) of a cosine velocity bell over [start, end] (paper eqs. 11-12):
/// s = τ - sin(2πτ)/2π, s' = (1 - cos 2πτ)/(end - start).
fn cosine_bell(t: Real, start: Real, end: Real) -> (Real, Real) {
    let length = end - start;
    let tau = (t - start) / length;
    if tau <= 0.0 {
        return (0.0, 0.0);
    }
    if tau >= 1.0 {
        return (1.0, 0.0);
    }
    let angle = 2.0 * std::f64::consts::PI * tau;
    (tau - angle.sin() / (2.0 * std::f64::consts::PI), (1.0 - angle.cos()) / length)
}

/// R_Φ for a phase where Φ moves in part of it, as a function of that phase's R_d: the
/// paper's curves (Figs. 6(c), 6(e), 6(f)) are not tabulated, so this is a placeholder
/// rising linearly to the paper's ≈ 80 % (not from the paper), drawn within ±4 % (the
/// paper's spread per R_d bin), and kept within [0.3, 0.8] so that the still part lasts
/// long enough to be a primitive of its own.
fn partial_ratio(r_d: Real, rng: &mut StdRng) -> Real {
    let centre = 0.3 + 0.25 * r_d;
    (centre + rng.random_range(-0.04..=0.04)).clamp(0.3, 0.8)
}

/// The ΦPO / PO-ΦPO / ΦPO-PO decision per phase (paper §5.2, METHODS.md §3.4): whether Φ
/// moves through all of phase 1 and all of phase 2.
fn whole_phases(handover: Handover, r_d: Real) -> (bool, bool) {
    match handover {
        Handover::PickUp => (true, false),
        // ΔΦ and ΔP are split evenly between the phases (there is no static posture model to
        // evaluate at P(T1)), so R_d1 = R_d2 = R_d; the tests are applied phase by phase.
        Handover::Delivery if r_d >= 1.6 => (true, true),
        Handover::Delivery => (r_d >= 1.8, r_d >= 1.6),
    }
}

fn phase_patterns(swivel_moves: bool, whole1: bool, whole2: bool) -> (Hamp, Hamp) {
    let (all, hand) = (Primitive::SWIVEL_POSITION_ORIENTATION, Primitive::POSITION_ORIENTATION);
    if !swivel_moves {
        return (Hamp(vec![hand]), Hamp(vec![hand]));
    }
    let phase1 = if whole1 { vec![all] } else { vec![hand, all] };
    let phase2 = if whole2 { vec![all] } else { vec![all, hand] };
    (Hamp(phase1), Hamp(phase2))
}

/// The goal swivel and Φ_M: the given one, or the middle of the widest feasible interval.
fn goal_swivel(robot: &Robot, target: &HandoverTarget) -> Result<(Real, Real), HampError> {
    let intervals = swivel_intervals(robot, &target.pw, &target.ow);
    let widest = intervals.as_ref().ok().and_then(|list| {
        list.iter().max_by(|a, b| (a.upper - a.lower).total_cmp(&(b.upper - b.lower))).copied()
    });
    let range = widest.map_or(std::f64::consts::PI, |i| (i.upper - i.lower).max(1e-6));
    match (target.swivel, widest) {
        (Some(swivel), _) => Ok((swivel, range)),
        (None, Some(i)) => Ok((0.5 * (i.lower + i.upper), range)),
        (None, None) => Err(HampError::Target(match intervals {
            Err(e) => e,
            Ok(_) => KinematicsError::Unreachable {
                distance: target.pw.norm(),
                min: 0.0,
                max: robot.upper_arm_length() + robot.forearm_length(),
            },
        })),
    }
}

/// The planned CPSA state and its rate [Pw', ω, Φ'] at time t.
struct Reference {
    start: CpsaState,
    travel: Vector3,
    rotation_axis: Vector3,
    rotation_angle: Real,
    swivel_change: Real,
    swivel_window: Option<(Real, Real)>,
    duration: Real,
}

impl Reference {
    fn at(&self, t: Real) -> (CpsaState, Vector7) {
        let (s, ds) = minimum_jerk(t / self.duration);
        let (o, d_o) = cosine_bell(t, 0.0, self.duration);
        let (phi, d_phi) = self.swivel_window.map_or((0.0, 0.0), |(a, b)| cosine_bell(t, a, b));
        let state = CpsaState {
            pw: self.start.pw + s * self.travel,
            ow: Rotation3::from_matrix_unchecked(
                rotation_about(&self.rotation_axis, o * self.rotation_angle)
                    * self.start.ow.matrix(),
            ),
            swivel: self.start.swivel + phi * self.swivel_change,
        };
        let mut rate = Vector7::zeros();
        rate.fixed_rows_mut::<3>(0).copy_from(&(self.travel * ds / self.duration));
        rate.fixed_rows_mut::<3>(3).copy_from(&(self.rotation_axis * self.rotation_angle * d_o));
        rate[6] = self.swivel_change * d_phi;
        (state, rate)
    }
}

/// Largest joint change between consecutive samples accepted as one IK branch (rad).
const BRANCH_JUMP: Real = 0.5;

/// Plans a handover from `start` to `target` with the HAMP method; `scene` is what the
/// clearance is measured against (the planner does not avoid obstacles: it reports them).
///
/// # Errors
/// [`HampError`]: an invalid rate, a singular start, no travel, no feasible goal swivel, or a
/// sample without an IK solution on the start's branch.
pub fn plan_handover(
    robot: &Robot,
    start: &JointVector,
    target: &HandoverTarget,
    scene: &CollisionScene,
    options: &HampOptions,
) -> Result<HampPlan, HampError> {
    if !(options.rate.is_finite() && options.rate > 0.0) {
        return Err(HampError::InvalidRate { rate: options.rate });
    }
    let start_state = cpsa_state(robot, &arm_pose(robot, start)).map_err(HampError::Start)?;
    let travel = target.pw - start_state.pw;
    let distance = travel.norm();
    if distance < 1e-6 {
        return Err(HampError::NoTravel);
    }
    let (swivel_goal, swivel_range) = goal_swivel(robot, target)?;
    let swivel_change = swivel_goal - start_state.swivel;
    let reach = robot.upper_arm_length() + robot.forearm_length();
    let r_d = (swivel_change.abs() / swivel_range) / (distance / reach);

    let duration = options.fitts.duration(distance);
    // P's minimum-jerk speed peaks at T/2 (eq. 13).
    let (t1, t2) = (0.5 * duration, 0.5 * duration);
    let mut rng = StdRng::seed_from_u64(options.seed);
    let (whole1, whole2) = whole_phases(options.handover, r_d);
    let r_phi1 = if whole1 { 1.0 } else { partial_ratio(r_d, &mut rng) };
    let r_phi2 = if whole2 { 1.0 } else { partial_ratio(r_d, &mut rng) };
    // One unimodal Φ bell over the union of the two phase windows (METHODS.md §3.5).
    let swivel_moves = swivel_change.abs() > 1e-9;
    let swivel_window = swivel_moves.then_some((t1 - r_phi1 * t1, t1 + r_phi2 * t2));
    let (phase1, phase2) = phase_patterns(swivel_moves, whole1, whole2);

    let rotation = rotation_log(&Rotation3::from_matrix_unchecked(
        target.ow.matrix() * start_state.ow.matrix().transpose(),
    ));
    let angle = rotation.norm();
    let reference = Reference {
        start: start_state,
        travel,
        rotation_axis: if angle > 0.0 { rotation / angle } else { Vector3::x() },
        rotation_angle: angle,
        swivel_change,
        swivel_window,
        duration,
    };

    let times = sample_times(0.0, duration, options.rate);
    let (mut positions, mut velocities) = (Vec::with_capacity(times.len()), Vec::new());
    let mut previous = *start;
    for &time in &times {
        let (state, rate) = reference.at(time);
        let ik_error = |source| HampError::Ik { time, source };
        let q = *ik_cpsa(robot, &state, Some(&previous))
            .map_err(ik_error)?
            .first()
            .ok_or(ik_error(KinematicsError::NonFinite { what: "IK solution" }))?;
        let jump = (q - previous).amax();
        if jump > BRANCH_JUMP {
            return Err(HampError::Discontinuous { time, jump });
        }
        let jacobian = cpsa_jacobian(robot, &arm_pose(robot, &q)).map_err(ik_error)?;
        let qd = jacobian.lu().solve(&rate).ok_or(HampError::SingularJacobian { time })?;
        positions.push(q);
        velocities.push(qd);
        previous = q;
    }
    let trajectory = Trajectory::new(times, positions, velocities)?;
    Ok(HampPlan {
        limit_violations: check_limits(&trajectory, robot, 1e-9),
        clearance: min_clearance(&trajectory, robot, scene),
        trajectory,
        phase1,
        phase2,
        duration,
        peak_time: t1,
        travel: distance,
        swivel: (start_state.swivel, swivel_goal),
        swivel_window,
        swivel_ratios: (r_phi1, r_phi2),
        duration_ratio: r_d,
    })
}
