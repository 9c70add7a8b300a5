//! Forward kinematics and the geometric and point Jacobians.

use crate::math::{
    DOF, Isometry, Jacobian3x7, Jacobian6x7, JointVector, Rotation3, Vector3, rotation_about,
};
use crate::robot::Robot;

/// Everything forward kinematics knows at one configuration, in {b}.
#[derive(Debug, Clone)]
pub struct ArmPose {
    /// `b_from_frame[k]`: moving frame k (0 is {b}, k the child of joint k).
    pub frames: [Isometry; DOF + 1],
    /// Joint axis directions.
    pub axes: [Vector3; DOF],
    /// A point of each joint axis (the joint frame origin).
    pub axis_points: [Vector3; DOF],
    /// Shoulder centre S.
    pub shoulder: Vector3,
    /// Elbow centre E.
    pub elbow: Vector3,
    /// Wrist centre W (= Pw).
    pub wrist: Vector3,
    /// Hand orientation Ow: columns f, p, f × p.
    pub hand: Rotation3,
}

impl ArmPose {
    /// The hand frame {W}: origin W, rotation Ow.
    pub fn hand_frame(&self) -> Isometry {
        Isometry::from_parts(self.wrist.into(), self.hand)
    }
}

/// Forward kinematics of every moving frame, the axes and S, E, W.
pub fn arm_pose(robot: &Robot, q: &JointVector) -> ArmPose {
    let mut frames = [Isometry::identity(); DOF + 1];
    let mut axes = [Vector3::zeros(); DOF];
    let mut axis_points = [Vector3::zeros(); DOF];
    for (k, joint) in robot.joints.iter().enumerate() {
        let parent = &frames[k];
        let origin = &joint.parent_from_joint;
        let translation = parent.translation.vector + parent.rotation * origin.translation.vector;
        let rotation = if origin.rotation == Rotation3::identity() {
            *parent.rotation.matrix()
        } else {
            parent.rotation.matrix() * origin.rotation.matrix()
        };
        axes[k] = rotation * joint.axis;
        axis_points[k] = translation;
        let spun = Rotation3::from_matrix_unchecked(rotation * rotation_about(&joint.axis, q[k]));
        frames[k + 1] = Isometry::from_parts(translation.into(), spun);
    }
    let s = &robot.structure;
    ArmPose {
        shoulder: Vector3::zeros(),
        elbow: frames[3].transform_point(&s.elbow_in_frame3.into()).coords,
        wrist: frames[6].transform_point(&s.wrist_in_frame6.into()).coords,
        hand: frames[DOF].rotation * robot.frame7_from_hand,
        frames,
        axes,
        axis_points,
    }
}

/// The pose in {b} of every link of the chain (in `robot.links` order).
pub fn link_poses(robot: &Robot, pose: &ArmPose) -> Vec<Isometry> {
    robot.links.iter().map(|l| pose.frames[l.frame] * l.frame_from_link).collect()
}

/// Jacobian of the velocity of `point` (in {b}) attached to moving frame `frame`.
pub fn point_jacobian(pose: &ArmPose, frame: usize, point: &Vector3) -> Jacobian3x7 {
    let mut j = Jacobian3x7::zeros();
    for i in 0..frame.min(DOF) {
        j.set_column(i, &pose.axes[i].cross(&(point - pose.axis_points[i])));
    }
    j
}

/// J_ge (6x7): linear velocity of W (rows 0-2), angular velocity of the hand (rows 3-5).
pub fn geometric_jacobian(pose: &ArmPose) -> Jacobian6x7 {
    let mut j = Jacobian6x7::zeros();
    for i in 0..DOF {
        let z = &pose.axes[i];
        // W rides on frame 6: joint 7 cannot move it.
        if i < 6 {
            j.fixed_view_mut::<3, 1>(0, i).copy_from(&z.cross(&(pose.wrist - pose.axis_points[i])));
        }
        j.fixed_view_mut::<3, 1>(3, i).copy_from(z);
    }
    j
}
