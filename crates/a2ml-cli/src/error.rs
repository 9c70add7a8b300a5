//! The CLI's error: a message and what kind of failure it reports, which
//! decides the exit code (0 success, 1 I/O, 2 invalid input, 3 a goal missed,
//! 4 planning failed).

use std::fmt;
use std::process::ExitCode;

use a2ml_core::RobotError;

/// Why a command failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CliError {
    /// A file could not be read or an output not written (exit code 1).
    Io(String),
    /// The input is invalid: bad URDF, no 7-DoF chain, unknown link,
    /// bad argument, a task file that is not valid (exit code 2).
    Input(String),
    /// A plan was made and written but misses a goal beyond tolerance
    /// (exit code 3): the results are usable, yet not what was asked.
    Missed(String),
    /// The solver could not produce a motion for a valid task: a QP step
    /// without solution, a singular state on the way (exit code 4). Nothing
    /// is written.
    Planning(String),
}

impl CliError {
    /// The process exit code for this error.
    pub fn exit_code(&self) -> ExitCode {
        match self {
            Self::Io(_) => ExitCode::from(1),
            Self::Input(_) => ExitCode::from(2),
            Self::Missed(_) => ExitCode::from(3),
            Self::Planning(_) => ExitCode::from(4),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io(message)
            | Self::Input(message)
            | Self::Missed(message)
            | Self::Planning(message) => f.write_str(message),
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

/// What became of the files of a command that takes several and reports
/// each one as it goes: the outcome is an I/O error if any file could not
/// be read or written, else invalid input if any file failed, else success.
#[derive(Debug, Default)]
pub struct FileTally {
    /// Files handled.
    pub files: usize,
    /// Files that could not be read.
    pub unreadable: usize,
    /// Files that could not be written.
    pub unwritable: usize,
    /// Files that are not valid.
    pub invalid: usize,
    /// Files not in canonical form (`a2ml fmt --check`).
    pub not_canonical: usize,
}

impl FileTally {
    /// The command's outcome; `failed` completes "1 of 3 files …".
    ///
    /// # Errors
    /// [`CliError::Io`] or [`CliError::Input`] with a one-line summary.
    pub fn finish(&self, failed: &str) -> Result<(), CliError> {
        let counts = [
            (self.unreadable, "unreadable"),
            (self.unwritable, "unwritable"),
            (self.invalid, "invalid"),
            (self.not_canonical, "not canonical"),
        ];
        let details: Vec<String> =
            counts.iter().filter(|(n, _)| *n > 0).map(|(n, what)| format!("{n} {what}")).collect();
        let failures: usize = counts.iter().map(|(n, _)| n).sum();
        if failures == 0 {
            return Ok(());
        }
        let noun = if self.files == 1 { "file" } else { "files" };
        let message =
            format!("{failures} of {} {noun} {failed}: {}", self.files, details.join(", "));
        if self.unreadable + self.unwritable > 0 {
            Err(CliError::Io(message))
        } else {
            Err(CliError::Input(message))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn io_wins_over_invalid() {
        let mut tally = FileTally { files: 3, ..FileTally::default() };
        assert_eq!(tally.finish("failed"), Ok(()));
        tally.invalid = 1;
        assert_eq!(
            tally.finish("failed the check"),
            Err(CliError::Input("1 of 3 files failed the check: 1 invalid".to_owned()))
        );
        tally.unreadable = 1;
        assert_eq!(
            tally.finish("failed"),
            Err(CliError::Io("2 of 3 files failed: 1 unreadable, 1 invalid".to_owned()))
        );
    }
}
