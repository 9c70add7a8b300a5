//! One module per subcommand, each with its clap arguments and a `run`
//! that calls the core and prints the result. [`run`] dispatches;
//! [`load_task`] is how the commands that take one task file read it.

pub mod analyze;
pub mod check;
pub mod compare;
pub mod explain;
pub mod fmt;
pub mod map;
pub mod plan;
pub mod plot;
pub mod report;
pub mod robot;

use std::path::Path;

use clap::Args;

use a2ml_core::language::{self, Limits, Task};

use crate::args::{Cli, Commands};
use crate::error::CliError;
use crate::output;
use crate::signals::Temporaries;

/// Runs the subcommand the command line names; outputs are staged through `temporaries`.
///
/// # Errors
/// The subcommand's [`CliError`].
pub fn run(cli: Cli, temporaries: &Temporaries) -> Result<(), CliError> {
    match cli.command {
        Commands::Robot(args) => robot::run(&args),
        Commands::Check(args) => check::run(&args),
        Commands::Fmt(args) => fmt::run(&args),
        Commands::Explain(args) => explain::run(&args),
        Commands::Plan(args) => plan::run(&args, temporaries),
        Commands::Analyze(args) => analyze::run(&args),
        Commands::Plot(args) => plot::run(&args),
        Commands::Report(args) => report::run(&args),
        Commands::Compare(args) => compare::run(&args),
        Commands::Map(args) => map::run(&args),
    }
}

/// The limits on what a task may ask for, shared by the commands that read tasks.
#[derive(Debug, Clone, Args)]
pub struct LimitArgs {
    /// Most samples a motion may have: its duration times the faster of the output and
    /// control rates.
    #[arg(long, value_name = "N", default_value_t = Limits::default().max_samples)]
    pub max_samples: u64,
    /// Most movement segments a task may decompose into.
    #[arg(long, value_name = "N", default_value_t = Limits::default().max_segments)]
    pub max_segments: usize,
    /// Most errors reported per file; the rest are counted.
    #[arg(long, value_name = "N", default_value_t = Limits::default().max_errors)]
    pub max_errors: usize,
    /// Most bytes read from a task file.
    #[arg(long, value_name = "N", default_value_t = Limits::default().max_input_bytes)]
    pub max_input_bytes: u64,
}

impl LimitArgs {
    /// The core's limits.
    pub fn limits(&self) -> Limits {
        Limits {
            max_samples: self.max_samples,
            max_segments: self.max_segments,
            max_errors: self.max_errors,
            max_input_bytes: self.max_input_bytes,
        }
    }
}

/// Reads and validates one task file within `limits`; returns the task and its text.
///
/// # Errors
/// [`CliError::Io`] when the file cannot be read (or is not UTF-8);
/// [`CliError::Input`] when it is too large or not a valid task, after its
/// located diagnostics have gone to stderr.
pub fn load_task(path: &Path, limits: &Limits) -> Result<(Task, String), CliError> {
    let text = language::read_source(path, limits).map_err(|e| {
        let message = format!("cannot read {}: {e}", path.display());
        match e {
            language::ReadError::TooLarge { .. } => CliError::Input(message),
            language::ReadError::Io(_) => CliError::Io(message),
        }
    })?;
    match language::parse_with(&text, Some(path), limits) {
        Ok(task) => Ok((task, text)),
        Err(diagnostics) => {
            output::report(&diagnostics.to_string());
            Err(CliError::Input(format!(
                "{} is not a valid task ({})",
                path.display(),
                output::count(diagnostics.items.len() + diagnostics.omitted, "problem")
            )))
        }
    }
}
