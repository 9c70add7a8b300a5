//! `a2ml check`: loads each task file (parse and validate, robot path
//! included) and says whether it is valid: `FILE: ok (task NAME, N actions)`
//! on stdout, or the located diagnostics on stderr.

use std::path::PathBuf;

use clap::Args;

use a2ml_core::language::{self, LanguageError};

use crate::error::{CliError, FileTally};
use crate::output;

/// Arguments of `a2ml check`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  a2ml check task.a2ml
  a2ml check examples/*.a2ml

Exit codes: 0 every file valid, 1 a file cannot be read, 2 a file is invalid
(1 wins when both happen).")]
pub struct CheckArgs {
    /// The task files.
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
    #[command(flatten)]
    pub limits: super::LimitArgs,
}

/// Runs `a2ml check`: every file is checked and reported, whatever the
/// others do.
///
/// # Errors
/// [`CliError::Io`] when a file cannot be read, else [`CliError::Input`]
/// when a file is invalid; either with a one-line summary.
pub fn run(args: &CheckArgs) -> Result<(), CliError> {
    let mut tally = FileTally::default();
    let limits = args.limits.limits();
    for path in &args.files {
        tally.files += 1;
        match language::load_with(path, &limits) {
            Ok(task) => output::print(&format!(
                "{}: ok (task {}, {})\n",
                path.display(),
                task.name,
                output::count(task.actions.len(), "action")
            ))?,
            Err(error @ LanguageError::Io { .. }) => {
                output::report(&format!("error: {error}"));
                tally.unreadable += 1;
            }
            Err(LanguageError::Invalid(diagnostics)) => {
                // A blank line keeps one file's diagnostics apart from the next.
                output::report(&format!("{diagnostics}\n"));
                tally.invalid += 1;
            }
        }
    }
    tally.finish("failed the check")
}
