//! The crate-wide error, one variant per fallible stage.

/// Any error of the library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Loading the robot model failed.
    #[error(transparent)]
    Robot(#[from] crate::robot::RobotError),
    /// A task file is unreadable or invalid.
    #[error(transparent)]
    Language(#[from] crate::language::LanguageError),
    /// A kinematic query has no answer.
    #[error(transparent)]
    Kinematics(#[from] crate::kinematics::KinematicsError),
}
