//! One module per subcommand, each with its clap arguments and a `run`
//! that calls the core and prints the result. [`run`] dispatches;
//! [`load_task`] is how the commands that take one task file read it.

pub mod check;
pub mod explain;
pub mod fmt;
pub mod map;
pub mod plan;
pub mod robot;

use std::path::Path;

use a2ml_core::language::{self, Task};

use crate::args::{Cli, Commands};
use crate::error::CliError;
use crate::output;

/// Runs the subcommand the command line names.
///
/// # Errors
/// The subcommand's [`CliError`].
pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Commands::Robot(args) => robot::run(&args),
        Commands::Check(args) => check::run(&args),
        Commands::Fmt(args) => fmt::run(&args),
        Commands::Explain(args) => explain::run(&args),
        Commands::Plan(args) => plan::run(&args),
        Commands::Map(args) => map::run(&args),
    }
}

/// Reads and validates one task file; returns the task and its text.
///
/// # Errors
/// [`CliError::Io`] when the file cannot be read (or is not UTF-8);
/// [`CliError::Input`] when it is not a valid task, after its located
/// diagnostics have gone to stderr.
pub fn load_task(path: &Path) -> Result<(Task, String), CliError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::Io(format!("cannot read {}: {e}", path.display())))?;
    match language::parse(&text, Some(path)) {
        Ok(task) => Ok((task, text)),
        Err(diagnostics) => {
            output::report(&diagnostics.to_string());
            Err(CliError::Input(format!(
                "{} is not a valid task ({})",
                path.display(),
                output::count(diagnostics.items.len(), "problem")
            )))
        }
    }
}
