//! a2ml: plans human-like motions for 7-DoF anthropomorphic arms from tasks
//! written in A2ML (Fang & Ding 2019).
//!
//! The modules follow the pipeline, data flowing one way: [`robot`] (URDF to an
//! arm model), [`kinematics`] (FK, CPSA and HAT states, Jacobians, IK, swivel
//! intervals), [`language`] (task files to a validated [`language::Task`]),
//! [`decompose`] (action order, types and segments), [`profile`] (bell profiles,
//! references, weights), [`collision`] (arm capsules against the scene),
//! [`solve`] (`plan`: each segment by the QP, an RRT, the swivel map or a
//! baseline, joined and checked), [`trajectory`] (sampled joint trajectories,
//! their joining and limit checks), [`metrics`] (human-likeness measures) and
//! [`output`] (MCAP, CSV, JSON, Parquet, SVG and HTML). [`math`] fixes the scalar
//! type and aliases, [`names`] suggests names, [`spelling`] gives every enum its one
//! spelling, [`error`] wraps each module's error; [`team`] holds the helper threads
//! that the wheel's batched kinematics share a large batch with.

pub mod collision;
pub mod decompose;
pub mod error;
pub mod kinematics;
pub mod language;
pub mod math;
pub mod metrics;
pub mod names;
pub mod output;
mod parallel;
pub mod profile;
pub mod robot;
pub mod solve;
pub mod spelling;
pub mod team;
pub mod trajectory;

pub use error::Error;
pub use kinematics::{CpsaState, HatState, KinematicsError};
pub use math::{JointVector, Real};
pub use robot::{Robot, RobotError, RobotOptions};
