//! The CLI's error: a message and whether it came from I/O or from the input,
//! which decides the exit code.

use std::fmt;
use std::process::ExitCode;

use a2ml_core::RobotError;

/// Why a command failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CliError {
    /// A file could not be read or an output not written (exit code 1).
    Io(String),
    /// The input is invalid: bad URDF, no 7-DoF chain, unknown link,
    /// bad argument (exit code 2).
    Input(String),
}

impl CliError {
    /// The process exit code for this error.
    pub fn exit_code(&self) -> ExitCode {
        match self {
            Self::Io(_) => ExitCode::from(1),
            Self::Input(_) => ExitCode::from(2),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io(message) | Self::Input(message) => f.write_str(message),
        }
    }
}

impl From<RobotError> for CliError {
    fn from(error: RobotError) -> Self {
        match error {
            RobotError::FileMissing { .. } | RobotError::Io { .. } => Self::Io(error.to_string()),
            other => Self::Input(other.to_string()),
        }
    }
}
