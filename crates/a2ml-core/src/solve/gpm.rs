//! The gradient projection method, A2ML's baseline (paper eq. 15-16, METHODS.md §5.2):
//! q' = J⁺X' + k(I - J⁺J)∇H, J⁺ = Jᵀ(JJᵀ)⁻¹ with J = J_ge, H(q) = -(q - q̄)ᵀ(q - q̄).
//!
//! Only the hand's path is given to GPM: in a CPSA segment the wrist follows its Pw reference
//! (the straight line to the goal, or the path written, e.g. a semi-elliptic `arc`, paper
//! fig. 12) and Ow its own (the geodesic rotation), both with the bell profile over the
//! segment; in HAT the straight line to the hand goal. The swivel angle is left to the
//! null-space term, which pulls every joint towards the middle of its range.

use super::control::{
    ControlError, ControlOptions, ControlRun, HandReference, Resolved, Resolver, Vector6,
    pose_error, pose_error_score, run,
};
use super::problem::SegmentProblem;
use super::report::Tolerance;
use crate::kinematics::{ArmPose, geometric_jacobian};
use crate::math::{Jacobian6x7, JointVector, Real};
use crate::robot::Robot;

/// Settings of GPM.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct GpmOptions {
    /// k, the gain of the null-space gradient (eq. 15), default 10. With ∇H = -2(q - q̄)
    /// the joints approach q̄ in the null space at 2k = 20 s⁻¹.
    pub null_space_gain: Real,
    /// K_fb (1/s) in X' = X'_d + K_fb (X_d - X), default 20 (the QP's gain). Eq. 15 is open
    /// loop: 0 gives the literal form, whose drift the report then shows. A project choice
    /// (METHODS.md §5.2).
    pub feedback_gain: Real,
    /// q̄, the posture H centres on; `None` (default) is the joint-range centres,
    /// (q_min + q_max)/2, the paper's "median angles".
    pub centre: Option<JointVector>,
}

impl Default for GpmOptions {
    fn default() -> Self {
        Self { null_space_gain: 10.0, feedback_gain: 20.0, centre: None }
    }
}

/// H(q) = -(q - q̄)ᵀ(q - q̄), the centring criterion (eq. 16): 0 at q̄, negative elsewhere.
pub fn centring(q: &JointVector, centre: &JointVector) -> Real {
    -(q - centre).norm_squared()
}

/// ∇H = -2(q - q̄).
pub fn centring_gradient(q: &JointVector, centre: &JointVector) -> JointVector {
    (q - centre) * -2.0
}

/// Eq. 15: q' = J⁺X' + k(I - J⁺J)∇H with J⁺ = Jᵀ(JJᵀ)⁻¹; `None` where JJᵀ is singular.
pub fn gpm_velocity(
    jacobian: &Jacobian6x7,
    twist: &Vector6,
    gradient: &JointVector,
    gain: Real,
) -> Option<JointVector> {
    let jjt = (jacobian * jacobian.transpose()).cholesky()?;
    let pseudo_inverse = |x: &Vector6| jacobian.transpose() * jjt.solve(x);
    // (I - J⁺J)∇H without forming the 7x7 projector.
    let null = gradient - pseudo_inverse(&(jacobian * gradient));
    Some(pseudo_inverse(twist) + null * gain)
}

/// GPM as a [`Resolver`]: the hand follows `reference`, joints centre on `centre`.
#[derive(Debug, Clone)]
pub struct Gpm {
    reference: HandReference,
    centre: JointVector,
    options: GpmOptions,
    tolerance: Tolerance,
}

impl Gpm {
    /// GPM on `robot` following `reference`.
    pub fn new(
        robot: &Robot,
        reference: HandReference,
        options: GpmOptions,
        tolerance: Tolerance,
    ) -> Self {
        Self {
            reference,
            centre: options.centre.unwrap_or_else(|| robot.middle()),
            options,
            tolerance,
        }
    }

    /// X' at t where the hand is at `pose`: the reference twist plus the feedback term.
    pub fn twist(&self, pose: &ArmPose, t: Real) -> Vector6 {
        let s = self.reference.sample(t);
        let mut twist = Vector6::zeros();
        twist.fixed_rows_mut::<3>(0).copy_from(&s.velocity);
        twist.fixed_rows_mut::<3>(3).copy_from(&s.angular_velocity);
        twist + pose_error(pose, &s.position, &s.rotation) * self.options.feedback_gain
    }
}

impl Resolver for Gpm {
    type Error = ControlError;

    fn resolve(
        &mut self,
        pose: &ArmPose,
        q: &JointVector,
        _velocity: &JointVector,
        t: Real,
    ) -> Result<Resolved, ControlError> {
        let jacobian = geometric_jacobian(pose);
        let twist = self.twist(pose, t);
        let gradient = centring_gradient(q, &self.centre);
        let velocity = gpm_velocity(&jacobian, &twist, &gradient, self.options.null_space_gain)
            .ok_or(ControlError::Singular { time: t, what: "hand Jacobian J Jᵀ" })?;
        let s = self.reference.sample(t);
        let error = pose_error_score(&pose_error(pose, &s.position, &s.rotation), &self.tolerance);
        Ok(Resolved { velocity, error })
    }
}

/// One segment by GPM from `q0`: the straight hand path to the segment's goal pose.
///
/// # Errors
/// [`ControlError`]: a goal without a hand pose, a singular J Jᵀ, invalid settings.
pub fn solve_segment(
    robot: &Robot,
    problem: &SegmentProblem,
    q0: &JointVector,
    options: &GpmOptions,
    control: &ControlOptions,
) -> Result<ControlRun, ControlError> {
    let start = crate::kinematics::arm_pose(robot, q0);
    let reference = HandReference::of_segment(robot, problem, (start.wrist, start.hand))?;
    let mut gpm = Gpm::new(robot, reference, *options, control.tolerance);
    run(robot, &mut gpm, q0, problem.duration, control)
}

#[cfg(test)]
mod tests {
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    use super::*;

    #[test]
    fn the_task_is_exact_and_the_null_space_term_raises_h() {
        let mut rng = StdRng::seed_from_u64(15);
        for _ in 0..100 {
            let j = Jacobian6x7::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let twist = Vector6::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let (q, centre) = (
                JointVector::from_fn(|_, _| rng.random_range(-2.0..2.0)),
                JointVector::from_fn(|_, _| rng.random_range(-1.0..1.0)),
            );
            let gradient = centring_gradient(&q, &centre);
            let v = gpm_velocity(&j, &twist, &gradient, 10.0).expect("full rank");
            assert!((j * v - twist).norm() <= 1e-10 * (1.0 + twist.norm()));
            // With X' = 0, dH/dt = ∇Hᵀq' = k‖(I - J⁺J)∇H‖² ≥ 0.
            let still = gpm_velocity(&j, &Vector6::zeros(), &gradient, 10.0).expect("full rank");
            assert!(gradient.dot(&still) >= -1e-12);
        }
    }
}
