//! Biomimetic weighted CLIK with virtual end-effectors (`biomimetic_clik`, METHODS.md §4):
//! the pen tracked by the β-weighted pseudo-inverse J_W⁺ = W⁻¹Jᵀ(JW⁻¹Jᵀ)⁻¹ with closed-loop
//! correction, v = p'_d + K(p_d - p), q' = J_W⁺v + (I - J_W⁺J)q'_a (eq. 3-6); the elbow and
//! wrist heights above the drawing plane as the lower layers.
//!
//! Layers, a project choice (METHODS.md §4.3): the paper integrates the elbow layer (joints
//! 1-3) and the wrist layer (joints 1-4) as joint trajectories of their own and pulls the arm
//! towards them by a gradient in the pen's null space; that pull cannot match both (the wrist
//! of the layers knows nothing of the pen), so the heights are only approached. Here each
//! layer is a prioritised task of the arm itself, in the null space of those above it: pen,
//! then wrist height, then elbow height, each row weighted by the same β. The elbow's row
//! involves joints 1-3 and, on a shoulder-elbow-wrist arm, the wrist's joints 1-4, as in the
//! paper; both heights are reached exactly whenever the pen leaves room, and the pen's motion
//! is the same with and without them (J N = 0).

use super::control::{
    ControlError, ControlOptions, ControlRun, HandReference, Resolved, Resolver, run,
};
use super::problem::SegmentProblem;
use super::report::Tolerance;
use crate::kinematics::{ArmPose, arm_pose, geometric_jacobian, point_jacobian};
use crate::math::{DOF, Jacobian3x7, JointVector, Matrix3, Matrix7, Real, Vector3, skew};
use crate::robot::Robot;

/// A 7x3 matrix: a pseudo-inverse of a 3x7 Jacobian.
pub type Matrix7x3 = nalgebra::SMatrix<Real, DOF, 3>;

/// Where a virtual end-effector's height is taken to.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HeightTarget {
    /// No layer.
    Off,
    /// This far (m) above the pen's height at the segment's start: the drawing plane.
    AbovePen(Real),
    /// This height (m) along the plane normal, from S.
    At(Real),
}

/// Settings of the weighted CLIK.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ClikOptions {
    /// K (1/s), the closed-loop gain on the pen error, default 30 (the paper's 30 I₃).
    pub gain: Real,
    /// β, each joint's involvement (W⁻¹ = diag β): 1 moves freely, 0 is frozen. Default
    /// (1, 1, 1, 1, 0.1, 0.1, 0.1): the paper says "close to 1" for joints 1-4 and "close to
    /// 0" for 5-7 without values (a project choice, METHODS.md §4.3).
    pub beta: JointVector,
    /// The pen tip in the hand frame {W} (m), default 0.1 m along f: the paper's "final link
    /// of 10 cm" (a project choice).
    pub pen: Vector3,
    /// The normal of the drawing plane in {b}, default z_b (a desk); heights are along it.
    pub plane_normal: Vector3,
    /// The elbow's layer, default 5 cm above the plane (METHODS.md §4.3's suggestion).
    pub elbow_height: HeightTarget,
    /// The wrist's layer, default 3 cm above the plane.
    pub wrist_height: HeightTarget,
    /// k_e = k_w (1/s), the layers' gain, default 200.
    pub layer_gain: Real,
    /// The fastest height change a layer asks for (m/s), default 0.5: with k = 200 s⁻¹ a
    /// centimetre's error would ask for 2 m/s (a project choice).
    pub layer_speed: Real,
    /// λ² in a layer's inverse (ãW⁻¹ãᵀ + λ²)⁻¹ (m²/rad²), default 1e-4: bounded steps where
    /// a height can no longer be changed without moving the pen.
    pub layer_damping: Real,
    /// k_a (1/s) of the remaining null-space motion q'_a = k_a ∂G/∂q, G = -(1/2n) Σ ((q_i -
    /// q̄_i)/(q_iM - q_im))², default 1 (METHODS.md §4.3). The paper's G tracks the layers'
    /// joints; with the layers as tasks, G centres the joints in their ranges.
    pub null_space_gain: Real,
    /// Project q'_a as (I - J_W⁺J)W⁻¹q'_a, so that frozen joints stay frozen; default false,
    /// the paper's literal (I - J_W⁺J)q'_a, through which a β = 0 joint still moves.
    pub freeze_null_space: bool,
}

impl Default for ClikOptions {
    fn default() -> Self {
        Self {
            gain: 30.0,
            beta: JointVector::from_column_slice(&[1.0, 1.0, 1.0, 1.0, 0.1, 0.1, 0.1]),
            pen: Vector3::new(0.1, 0.0, 0.0),
            plane_normal: Vector3::z(),
            elbow_height: HeightTarget::AbovePen(0.05),
            wrist_height: HeightTarget::AbovePen(0.03),
            layer_gain: 200.0,
            layer_speed: 0.5,
            layer_damping: 1e-4,
            null_space_gain: 1.0,
            freeze_null_space: false,
        }
    }
}

/// J_W⁺ = W⁻¹Jᵀ(JW⁻¹Jᵀ)⁻¹ with W⁻¹ = diag(β) (eq. 3); `None` where JW⁻¹Jᵀ is singular.
pub fn weighted_pseudo_inverse(jacobian: &Jacobian3x7, beta: &JointVector) -> Option<Matrix7x3> {
    let weighted = Matrix7::from_diagonal(beta) * jacobian.transpose();
    let inner: Matrix3 = jacobian * weighted;
    Some(weighted * inner.cholesky()?.inverse())
}

/// One lower-priority row task: q' + N ã⁺(v - a q'), ã = aN, ã⁺ = W⁻¹ãᵀ/(ãW⁻¹ãᵀ + λ²), and
/// the projector that follows, N(I - ã⁺ã). Tasks above keep what they had, since their
/// Jacobians annihilate N.
fn prioritised(
    velocity: &JointVector,
    projector: &Matrix7,
    row: &JointVector,
    target: Real,
    beta: &JointVector,
    damping: Real,
) -> (JointVector, Matrix7) {
    let projected: JointVector = projector.transpose() * row;
    let weighted = projected.component_mul(beta);
    let inverse = weighted / (projected.dot(&weighted) + damping);
    let next = velocity + projector * inverse * (target - row.dot(velocity));
    (next, projector * (Matrix7::identity() - inverse * projected.transpose()))
}

/// The pen tip in {b} where the hand is at `pose`.
pub fn pen_point(pose: &ArmPose, pen: &Vector3) -> Vector3 {
    pose.wrist + pose.hand * pen
}

/// The pen's Jacobian: v_W + ω × r with r = Ow·pen, from J_ge.
pub fn pen_jacobian(pose: &ArmPose, pen: &Vector3) -> Jacobian3x7 {
    let j = geometric_jacobian(pose);
    let r = pose.hand * pen;
    j.fixed_rows::<3>(0) - skew(&r) * j.fixed_rows::<3>(3)
}

/// The weighted CLIK as a [`Resolver`]: the pen follows the hand reference's rigid point.
#[derive(Debug, Clone)]
pub struct Clik {
    reference: HandReference,
    options: ClikOptions,
    /// Heights (m, along the normal) of the elbow and wrist layers, when on.
    elbow_target: Option<Real>,
    wrist_target: Option<Real>,
    centre: JointVector,
    /// 1/(n (q_M - q_m)²) per joint, the weights of ∂G/∂q.
    range_weights: JointVector,
    tolerance: Tolerance,
}

impl Clik {
    /// CLIK on `robot` with the pen following `reference`'s rigid point at `options.pen`.
    pub fn new(
        robot: &Robot,
        reference: HandReference,
        options: ClikOptions,
        tolerance: Tolerance,
    ) -> Self {
        let normal = options.plane_normal.normalize();
        let options = ClikOptions { plane_normal: normal, ..options };
        let plane = normal.dot(&Self::pen_reference(&reference, &options.pen, 0.0).0);
        let resolve = |h: HeightTarget| match h {
            HeightTarget::Off => None,
            HeightTarget::AbovePen(d) => Some(plane + d),
            HeightTarget::At(y) => Some(y),
        };
        let range = robot.upper() - robot.lower();
        Self {
            reference,
            elbow_target: resolve(options.elbow_height),
            wrist_target: resolve(options.wrist_height),
            options,
            centre: robot.middle(),
            range_weights: range.map(|r| 1.0 / (DOF as Real * r * r)),
            tolerance,
        }
    }

    /// The pen's reference position and velocity at t.
    fn pen_reference(reference: &HandReference, pen: &Vector3, t: Real) -> (Vector3, Vector3) {
        let s = reference.sample(t);
        let r = s.rotation * pen;
        (s.position + r, s.velocity + s.angular_velocity.cross(&r))
    }

    /// The pen position asked for at t (m, {b}).
    pub fn pen_target(&self, t: Real) -> Vector3 {
        Self::pen_reference(&self.reference, &self.options.pen, t).0
    }

    /// The elbow and wrist heights the layers aim at (m along the plane normal), when on.
    pub fn height_targets(&self) -> (Option<Real>, Option<Real>) {
        (self.elbow_target, self.wrist_target)
    }
}

impl Resolver for Clik {
    type Error = ControlError;

    fn resolve(
        &mut self,
        pose: &ArmPose,
        q: &JointVector,
        _velocity: &JointVector,
        t: Real,
    ) -> Result<Resolved, ControlError> {
        let o = &self.options;
        let (target, target_velocity) = Self::pen_reference(&self.reference, &o.pen, t);
        let error = target - pen_point(pose, &o.pen);
        let jacobian = pen_jacobian(pose, &o.pen);
        let inverse = weighted_pseudo_inverse(&jacobian, &o.beta)
            .ok_or(ControlError::Singular { time: t, what: "pen Jacobian J W⁻¹ Jᵀ" })?;
        let mut velocity = inverse * (target_velocity + error * o.gain);
        let mut projector = Matrix7::identity() - inverse * jacobian;
        let n = o.plane_normal;
        let layers = [
            (
                self.wrist_target,
                (geometric_jacobian(pose).fixed_rows::<3>(0).transpose() * n, pose.wrist),
            ),
            (self.elbow_target, (point_jacobian(pose, 3, &pose.elbow).transpose() * n, pose.elbow)),
        ];
        // The heights are part of the task: settling waits for them too, or for their stall.
        let mut worst = error.norm();
        for (height, (row, point)) in layers {
            if let Some(height) = height {
                worst = worst.max((height - n.dot(&point)).abs());
                let v =
                    (o.layer_gain * (height - n.dot(&point))).clamp(-o.layer_speed, o.layer_speed);
                (velocity, projector) =
                    prioritised(&velocity, &projector, &row, v, &o.beta, o.layer_damping);
            }
        }
        let ascent = (q - self.centre).component_mul(&self.range_weights) * -o.null_space_gain;
        let ascent = if o.freeze_null_space { ascent.component_mul(&o.beta) } else { ascent };
        velocity += projector * ascent;
        Ok(Resolved { velocity, error: worst / self.tolerance.position })
    }
}

/// One segment by CLIK from `q0`: the pen follows the segment's own hand path
/// ([`HandReference::of_segment`]).
///
/// # Errors
/// [`ControlError`]: a goal without a hand pose, a singular pen Jacobian, invalid settings.
pub fn solve_segment(
    robot: &Robot,
    problem: &SegmentProblem,
    q0: &JointVector,
    options: &ClikOptions,
    control: &ControlOptions,
) -> Result<ControlRun, ControlError> {
    let start = arm_pose(robot, q0);
    let reference = HandReference::of_segment(robot, problem, (start.wrist, start.hand))?;
    let mut clik = Clik::new(robot, reference, *options, control.tolerance);
    run(robot, &mut clik, q0, problem.duration, control)
}

#[cfg(test)]
mod tests {
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    use super::*;

    #[test]
    fn the_weighted_projector_annihilates_the_task_and_frozen_rows_are_zero() {
        let mut rng = StdRng::seed_from_u64(4);
        for trial in 0..200 {
            let j = Jacobian3x7::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let mut beta = JointVector::from_fn(|_, _| rng.random_range(0.05..1.0));
            if trial % 2 == 0 {
                beta[rng.random_range(0..DOF)] = 0.0;
                beta[rng.random_range(0..DOF)] = 0.0;
            }
            let inverse = weighted_pseudo_inverse(&j, &beta).expect("full rank");
            let z = JointVector::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let projector = Matrix7::identity() - inverse * j;
            assert!((j * (projector * z)).norm() <= 1e-12 * z.norm());
            assert!((j * inverse - Matrix3::identity()).amax() < 1e-12);
            for i in (0..DOF).filter(|&i| beta[i] == 0.0) {
                assert_eq!(inverse.row(i).amax(), 0.0, "row {i} of a frozen joint");
            }
        }
    }

    #[test]
    fn a_prioritised_row_is_met_without_disturbing_the_task_above() {
        let mut rng = StdRng::seed_from_u64(5);
        for _ in 0..100 {
            let j = Jacobian3x7::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let beta = JointVector::from_fn(|_, _| rng.random_range(0.1..1.0));
            let inverse = weighted_pseudo_inverse(&j, &beta).expect("full rank");
            let v = Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let q1 = inverse * v;
            let row = JointVector::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let projector = Matrix7::identity() - inverse * j;
            let (q2, next) = prioritised(&q1, &projector, &row, 0.7, &beta, 0.0);
            assert!((j * q2 - v).norm() < 1e-10);
            assert!((row.dot(&q2) - 0.7).abs() < 1e-9);
            assert!((j * next).amax() < 1e-10 && (row.transpose() * next).amax() < 1e-9);
        }
    }
}
