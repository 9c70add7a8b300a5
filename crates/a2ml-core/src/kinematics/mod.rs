//! Forward and inverse kinematics in joint space and in the two
//! representation spaces of the paper: CPSA (Pw, Ow, θsw) and HAT (Os, θe, Ow).
//!
//! Entry points: [`arm_pose`] (everything FK knows at q), the state
//! functions [`cpsa_state`] / [`hat_state`] with their 7x7 Jacobians, the
//! mapping [`cpsa_to_hat`] / [`hat_to_cpsa`], IK [`ik_cpsa`] / [`ik_hat`]
//! and [`swivel_intervals`]; [`AlignedChain`] for the frames alone (the collision model);
//! [`BatchedChain`] for FK, J_ge and CPSA states of many configurations at once. Frames and
//! signs follow docs/design.md §2-3: all in {b}, origin at the shoulder centre.

mod error;
mod fk;
mod frames;
mod ik;
mod lanes;
mod spaces;
mod swivel;

pub use error::{KinematicsError, Singularity};
pub use fk::{ArmPose, arm_pose, geometric_jacobian, link_poses, point_jacobian};
pub use frames::{AlignedChain, Frame};
pub use ik::{
    IkOptions, ik_cpsa, ik_cpsa_nearest, ik_cpsa_with, ik_hat, ik_hat_nearest, ik_hat_with,
};
pub use lanes::{BatchedChain, FRAME_VALUES, JACOBIAN_VALUES, LANES};
pub use spaces::{
    CpsaState, HatState, cpsa_jacobian, cpsa_state, cpsa_to_hat, hat_jacobian, hat_state,
    hat_to_cpsa, swivel_angle,
};
pub use swivel::{SwivelInterval, swivel_intervals};
