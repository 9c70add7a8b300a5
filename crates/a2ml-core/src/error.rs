//! The crate-wide error, one variant per fallible stage, in pipeline order.

/// Any error of the library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Loading the robot model failed.
    #[error(transparent)]
    Robot(#[from] crate::robot::RobotError),
    /// A kinematic query has no answer.
    #[error(transparent)]
    Kinematics(#[from] crate::kinematics::KinematicsError),
    /// A task file is unreadable or invalid.
    #[error(transparent)]
    Language(#[from] crate::language::LanguageError),
    /// A task cannot be decomposed into actions and segments.
    #[error(transparent)]
    Decompose(#[from] crate::decompose::DecomposeError),
    /// A reference profile cannot be built.
    #[error(transparent)]
    Profile(#[from] crate::profile::ProfileError),
    /// A trajectory cannot be built or joined.
    #[error(transparent)]
    Trajectory(#[from] crate::trajectory::TrajectoryError),
    /// A task cannot be planned.
    #[error(transparent)]
    Solve(#[from] crate::solve::SolveError),
    /// An output file cannot be written.
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    /// A plan file cannot be read back.
    #[error(transparent)]
    Read(#[from] crate::output::ReadError),
}
