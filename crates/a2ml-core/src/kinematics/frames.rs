//! The moving frames alone, for the collision model's many configurations: no Jacobian, no
//! hand frame, no arm triangle, only the frames up to the last one a caller needs, each turned
//! so that its joint's axis is z ([`AlignedChain`]). [`super::arm_pose`] computes everything
//! FK knows; this computes the least a clearance check needs.

use crate::math::{DOF, JointVector, Matrix3, PI, Rotation3, Vector3};
use crate::robot::Robot;

/// Forward kinematics of the moving frames up to a last one (the last carrying a capsule for
/// the collision model), in aligned
/// frames: each frame k+1 turned so that the axis of joint k is its z, which makes a joint's
/// turn a two-column update and folds the joint axes into constant transforms.
///
/// With F the moving frames of [`crate::kinematics::arm_pose`] and A_k a rotation taking z onto
/// joint k's axis u_k: R(u_k, q) A_k = A_k Rz(q), so the aligned frame G_{k+1} = F_{k+1} A_k is
/// G_k (A_{k−1}ᵀ P_k A_k) Rz(q_k), P_k being the joint's parent-from-joint transform.
#[derive(Debug, Clone)]
pub struct AlignedChain {
    /// A_{k−1}ᵀ P_k A_k per joint, up to the last frame needed.
    steps: Vec<Frame>,
    /// A_{k−1}ᵀ per frame k (the identity for {b}).
    pub aligned_from_frame: [Matrix3; DOF + 1],
}

/// A rigid transform: rotation then translation.
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    /// The frame's axes in {b}.
    pub rotation: Matrix3,
    /// Its origin in {b} (m).
    pub translation: Vector3,
}

impl Frame {
    /// {b} itself.
    pub fn identity() -> Self {
        Self { rotation: Matrix3::identity(), translation: Vector3::zeros() }
    }

    /// The point `p` of the frame, in {b}.
    pub fn apply(&self, p: &Vector3) -> Vector3 {
        self.rotation * p + self.translation
    }
}

impl AlignedChain {
    /// The chain of `robot` up to moving frame `last`.
    pub fn new(robot: &Robot, last: usize) -> Self {
        let z = Vector3::z();
        let align: Vec<Matrix3> = robot
            .joints
            .iter()
            .map(|j| {
                Rotation3::rotation_between(&z, &j.axis)
                    // The axis is -z: half a turn about x.
                    .unwrap_or_else(|| Rotation3::from_axis_angle(&Vector3::x_axis(), PI))
                    .into_inner()
            })
            .collect();
        let mut aligned_from_frame = [Matrix3::identity(); DOF + 1];
        for k in 1..=DOF {
            aligned_from_frame[k] = align[k - 1].transpose();
        }
        let steps = robot.joints[..last]
            .iter()
            .enumerate()
            .map(|(k, joint)| {
                let p = &joint.parent_from_joint;
                let before = aligned_from_frame[k];
                Frame {
                    rotation: before * p.rotation.matrix() * align[k],
                    translation: before * p.translation.vector,
                }
            })
            .collect();
        Self { steps, aligned_from_frame }
    }

    /// The aligned frames at `q`, `b_from_aligned`; those past the last needed are left at
    /// the identity.
    pub fn frames(&self, q: &JointVector) -> [Frame; DOF + 1] {
        let mut frames = [Frame::identity(); DOF + 1];
        for (k, step) in self.steps.iter().enumerate() {
            let parent = frames[k];
            let m = parent.rotation * step.rotation;
            let (s, c) = q[k].sin_cos();
            let (x, y) = (m.column(0), m.column(1));
            frames[k + 1] = Frame {
                rotation: Matrix3::from_columns(&[
                    x * c + y * s,
                    y * c - x * s,
                    m.column(2).into(),
                ]),
                translation: parent.translation + parent.rotation * step.translation,
            };
        }
        frames
    }
}
