//! a2ml: plans human-like motions for 7-DoF anthropomorphic arms from tasks
//! written in A2ML (Fang & Ding 2019).
//!
//! The modules follow the pipeline: [`robot`] (URDF to an arm model),
//! [`kinematics`] (FK, CPSA and HAT states, Jacobians, IK), [`language`]
//! (task files to a validated [`language::Task`]), [`decompose`] (action
//! order and types), [`profile`] (bell profiles, references, weights and
//! the joining of segments), [`collision`] (arm capsules against the scene).

pub mod collision;
pub mod decompose;
pub mod error;
pub mod kinematics;
pub mod language;
pub mod math;
pub mod metrics;
pub mod names;
pub mod output;
pub mod profile;
pub mod robot;
pub mod solve;
pub mod spelling;
pub mod trajectory;

pub use error::Error;
pub use kinematics::{CpsaState, HatState, KinematicsError};
pub use math::{JointVector, Real};
pub use robot::{Robot, RobotError, RobotOptions};
