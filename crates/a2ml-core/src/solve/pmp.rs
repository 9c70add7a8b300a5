//! λ0-PMP, the extended Passive Motion Paradigm (`lambda0_pmp`, METHODS.md §2), with PMP1 and
//! PMP2 for comparison:
//!
//! ```text
//! λ0-PMP: q' = W⁻¹(Jᵀ(F + λ0) - τ_el),  λ0 = B J W⁻¹ τ_el,  B = (J W⁻¹ Jᵀ)⁻¹
//! PMP1:   q' = W⁻¹JᵀF                    PMP2: q' = W⁻¹(JᵀF - τ_el)
//! τ_el = K_J(q - q*),  F = K(t)(x_d - x),  W = τ0 K_J,
//! K(t) = k(1 - e^(-t/τ) - (t/τ)e^(-t/τ)),  τ = τ0 = T/5,  k = b_max/τ0 (eq. 10)
//! ```
//!
//! λ0-PMP moves the task as B x' = K(t)(x_d - x) and settles where x = x_d with the posture
//! nearest q* in the K_J metric, whatever the way there (Donders' law). The formulas are
//! written for any m < n, so the paper's 3-DoF wrist runs through the same functions as the
//! 7-DoF arms.

use nalgebra::{DMatrix, DVector};

use super::control::{
    ControlError, ControlOptions, ControlRun, Resolved, Resolver, hand_goal, pose_error,
    pose_error_score, run,
};
use super::problem::SegmentProblem;
use super::report::Tolerance;
use crate::kinematics::{ArmPose, arm_pose, geometric_jacobian};
use crate::math::{DOF, JointVector, Real, Rotation3, Vector3};
use crate::robot::Robot;

/// Which of the paper's three models (its Fig. 1B).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PmpVariant {
    /// q' = W⁻¹(Jᵀ(F + λ0) - τ_el): exact task dynamics, posture by Donders' law.
    Lambda0,
    /// q' = W⁻¹JᵀF: no elastic term; the posture depends on the way there.
    Pmp1,
    /// q' = W⁻¹(JᵀF - τ_el): the elastic term fights the task, leaving an error.
    Pmp2,
}

/// The task x the spring pulls: m = 3 or m = 6.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PmpTask {
    /// x = Pw (m = 3); the hand's orientation is left to the posture.
    Position,
    /// x = (Pw, Ow) (m = 6), the rotation error log(R_d Rᵀ) with J = J_ge.
    Pose,
}

/// Settings of PMP. The paper's experiment is a 3-DoF wrist; its use on a 7-DoF arm is a
/// project choice (METHODS.md §2.4), each item below.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PmpOptions {
    /// The model, default λ0-PMP.
    pub variant: PmpVariant,
    /// The task, default the hand pose (m = 6), so that a segment's Ow goal is kept.
    pub task: PmpTask,
    /// diag K_J (N·m/rad); `None` (default) is isotropic with trace 4 N·m/rad, the paper's
    /// passive wrist stiffness. Only the ratios shape the motion.
    pub joint_stiffness: Option<JointVector>,
    /// q*, the rest posture; `None` (default) is the joint-range centres.
    pub rest_posture: Option<JointVector>,
    /// τ0 = τ as a fraction of the segment's duration T, default 1/5 (the paper's T/5).
    pub time_constant_fraction: Real,
    /// k, the final stiffness of the task spring; `None` (default) is eq. 10's b_max/τ0 with
    /// b_max the largest eigenvalue of B at the segment's start (METHODS.md §2.4: the
    /// paper's Fig. 3 uses 22.5 instead).
    pub stiffness: Option<Real>,
}

impl Default for PmpOptions {
    fn default() -> Self {
        Self {
            variant: PmpVariant::Lambda0,
            task: PmpTask::Pose,
            joint_stiffness: None,
            rest_posture: None,
            time_constant_fraction: 0.2,
            stiffness: None,
        }
    }
}

/// The stiffness ramp K(t)/I (eq. 8): k(1 - e^(-t/τ) - (t/τ)e^(-t/τ)), 0 at t = 0 with zero
/// slope, → k.
pub fn stiffness_ramp(t: Real, k: Real, tau: Real) -> Real {
    let s = t.max(0.0) / tau;
    k * (1.0 - (-s).exp() * (1.0 + s))
}

/// B(q) = (J W⁻¹ Jᵀ)⁻¹, the task-space damping, with W⁻¹ given by its diagonal; `None` where
/// J W⁻¹ Jᵀ is singular.
pub fn task_damping(jacobian: &DMatrix<Real>, w_inverse: &DVector<Real>) -> Option<DMatrix<Real>> {
    let weighted = DMatrix::from_diagonal(w_inverse) * jacobian.transpose();
    Some((jacobian * weighted).cholesky()?.inverse())
}

/// q' of `variant` (METHODS.md §2.1) from J (m×n), W⁻¹'s diagonal, τ_el = K_J(q - q*) and
/// F; `None` where J W⁻¹ Jᵀ is singular (λ0-PMP only needs it).
pub fn pmp_velocity(
    variant: PmpVariant,
    jacobian: &DMatrix<Real>,
    w_inverse: &DVector<Real>,
    elastic: &DVector<Real>,
    force: &DVector<Real>,
) -> Option<DVector<Real>> {
    let torque = match variant {
        PmpVariant::Pmp1 => jacobian.transpose() * force,
        PmpVariant::Pmp2 => jacobian.transpose() * force - elastic,
        PmpVariant::Lambda0 => {
            // λ0 = B J W⁻¹ τ_el (eq. 4), solved rather than inverted.
            let weighted = DMatrix::from_diagonal(w_inverse) * jacobian.transpose();
            let lambda0 = (jacobian * weighted)
                .cholesky()?
                .solve(&(jacobian * elastic.component_mul(w_inverse)));
            jacobian.transpose() * (force + lambda0) - elastic
        }
    };
    Some(torque.component_mul(w_inverse))
}

/// λ_max(B(q)), the b_max of eq. 10.
pub fn largest_damping(jacobian: &DMatrix<Real>, w_inverse: &DVector<Real>) -> Option<Real> {
    let b = task_damping(jacobian, w_inverse)?;
    Some(b.symmetric_eigen().eigenvalues.max())
}

/// PMP on a 7-DoF arm as a [`Resolver`], towards one hand target from the segment's start.
#[derive(Debug, Clone)]
pub struct Pmp {
    variant: PmpVariant,
    task: PmpTask,
    target: (Vector3, Rotation3),
    stiffness: JointVector,
    w_inverse: DVector<Real>,
    rest: JointVector,
    /// τ (s) and k of the ramp.
    tau: Real,
    k: Real,
    tolerance: Tolerance,
}

impl Pmp {
    /// PMP on `robot` from `q0` to the hand `target` over `duration` (s).
    ///
    /// # Errors
    /// [`ControlError::InvalidOptions`] for a non-positive stiffness or time constant;
    /// [`ControlError::Singular`] when b_max is asked for where B does not exist.
    pub fn new(
        robot: &Robot,
        q0: &JointVector,
        target: (Vector3, Rotation3),
        duration: Real,
        options: &PmpOptions,
        tolerance: Tolerance,
    ) -> Result<Self, ControlError> {
        let invalid = |reason| ControlError::InvalidOptions { reason };
        let stiffness =
            options.joint_stiffness.unwrap_or_else(|| JointVector::repeat(4.0 / DOF as Real));
        if !stiffness.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(invalid("every joint stiffness must be positive"));
        }
        let tau = options.time_constant_fraction * duration;
        if !(tau.is_finite() && tau > 0.0) {
            return Err(invalid("the time constant must be positive"));
        }
        // W = τ0 K_J (eq. 7).
        let w_inverse = DVector::from_iterator(DOF, stiffness.iter().map(|s| 1.0 / (tau * s)));
        let k = match options.stiffness {
            Some(k) if k.is_finite() && k > 0.0 => k,
            Some(_) => return Err(invalid("the task stiffness must be positive")),
            None => {
                let j = task_jacobian(options.task, &arm_pose(robot, q0));
                largest_damping(&j, &w_inverse)
                    .ok_or(ControlError::Singular { time: 0.0, what: "task damping B" })?
                    / tau
            }
        };
        Ok(Self {
            variant: options.variant,
            task: options.task,
            target,
            stiffness,
            w_inverse,
            rest: options.rest_posture.unwrap_or_else(|| robot.middle()),
            tau,
            k,
            tolerance,
        })
    }

    /// k, the ramp's final stiffness.
    pub fn stiffness(&self) -> Real {
        self.k
    }

    /// K(t)/I.
    pub fn ramp(&self, t: Real) -> Real {
        stiffness_ramp(t, self.k, self.tau)
    }

    /// The task error x_d - x at `pose` (m; and rad for the pose task).
    pub fn task_error(&self, pose: &ArmPose) -> DVector<Real> {
        let e = pose_error(pose, &self.target.0, &self.target.1);
        match self.task {
            PmpTask::Position => DVector::from_column_slice(&e.as_slice()[..3]),
            PmpTask::Pose => DVector::from_column_slice(e.as_slice()),
        }
    }

    /// B(q) at `pose`.
    pub fn damping(&self, pose: &ArmPose) -> Option<DMatrix<Real>> {
        task_damping(&task_jacobian(self.task, pose), &self.w_inverse)
    }
}

/// J of the task: the rows of J_ge for Pw, or all six.
pub fn task_jacobian(task: PmpTask, pose: &ArmPose) -> DMatrix<Real> {
    let j = geometric_jacobian(pose);
    let rows = match task {
        PmpTask::Position => 3,
        PmpTask::Pose => 6,
    };
    DMatrix::from_fn(rows, DOF, |r, c| j[(r, c)])
}

impl Resolver for Pmp {
    type Error = ControlError;

    fn resolve(
        &mut self,
        pose: &ArmPose,
        q: &JointVector,
        _velocity: &JointVector,
        t: Real,
    ) -> Result<Resolved, ControlError> {
        let error = self.task_error(pose);
        let force = &error * self.ramp(t);
        let elastic = DVector::from_iterator(
            DOF,
            (q - self.rest).component_mul(&self.stiffness).iter().copied(),
        );
        let jacobian = task_jacobian(self.task, pose);
        let velocity = pmp_velocity(self.variant, &jacobian, &self.w_inverse, &elastic, &force)
            .ok_or(ControlError::Singular { time: t, what: "J W⁻¹ Jᵀ" })?;
        let score = match self.task {
            PmpTask::Pose => {
                pose_error_score(&pose_error(pose, &self.target.0, &self.target.1), &self.tolerance)
            }
            PmpTask::Position => error.norm() / self.tolerance.position,
        };
        Ok(Resolved { velocity: JointVector::from_column_slice(velocity.as_slice()), error: score })
    }

    /// k λ_max(J W⁻¹ Jᵀ): the task moves as x' = B⁻¹K(t)(x_d - x), and for m = 6 (metres and
    /// radians together) J W⁻¹ Jᵀ is badly conditioned, so with eq. 10's k this rate can
    /// reach thousands per second.
    fn fastest_rate(&self, pose: &ArmPose) -> Real {
        let j = task_jacobian(self.task, pose);
        let weighted = &j * DMatrix::from_diagonal(&self.w_inverse) * j.transpose();
        // The elastic null-space motion decays at W⁻¹K_J = 1/τ0.
        (self.k * weighted.symmetric_eigen().eigenvalues.max()).max(1.0 / self.tau)
    }
}

/// One segment by PMP from `q0` towards the segment's goal hand pose; the clock of the ramp
/// starts at the segment's start.
///
/// # Errors
/// [`ControlError`]: a goal without a hand pose, a singular J W⁻¹ Jᵀ, invalid settings.
pub fn solve_segment(
    robot: &Robot,
    problem: &SegmentProblem,
    q0: &JointVector,
    options: &PmpOptions,
    control: &ControlOptions,
) -> Result<ControlRun, ControlError> {
    let target = hand_goal(robot, problem)?;
    let mut pmp = Pmp::new(robot, q0, target, problem.duration, options, control.tolerance)?;
    run(robot, &mut pmp, q0, problem.duration, control)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramp_has_the_papers_values() {
        for (t, expected) in [(1.0, 0.264), (2.0, 0.594), (3.0, 0.801), (5.0, 0.960)] {
            assert!((stiffness_ramp(t * 0.08, 1.0, 0.08) - expected).abs() < 5e-4, "{t}");
        }
        assert_eq!(stiffness_ramp(0.0, 22.5, 0.08), 0.0);
    }

    #[test]
    fn lambda0_cancels_the_elastic_term_in_the_task() {
        let j = DMatrix::from_row_slice(2, 4, &[1.0, 0.2, -0.3, 0.5, 0.1, -1.0, 0.4, 0.7]);
        let w_inverse = DVector::from_column_slice(&[2.0, 1.0, 0.5, 3.0]);
        let elastic = DVector::from_column_slice(&[0.3, -0.2, 0.8, 0.1]);
        let force = DVector::from_column_slice(&[0.5, -1.5]);
        let v = pmp_velocity(PmpVariant::Lambda0, &j, &w_inverse, &elastic, &force).expect("rank");
        let b = task_damping(&j, &w_inverse).expect("rank");
        assert!((b * (&j * v) - force).amax() < 1e-12);
    }
}
