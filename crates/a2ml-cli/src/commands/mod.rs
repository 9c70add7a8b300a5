//! One module per subcommand, each with its clap arguments and a `run`
//! that calls the core and prints the result. [`run`] dispatches.

pub mod check;
pub mod explain;
pub mod fmt;
pub mod robot;

use crate::args::{Cli, Commands};
use crate::error::CliError;

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
    }
}
