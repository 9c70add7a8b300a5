//! `a2ml report`: plans a task file and writes one self-contained HTML page about it through
//! the core's [`output::report`](a2ml_core::output::report): the task, its decomposition (as
//! `a2ml explain` prints it), the segment table, the plots and the motion played back.

use std::path::PathBuf;

use clap::Args;

use a2ml_core::decompose::{self, DecomposeOptions};
use a2ml_core::output::report::{ReportInput, write_report};

use super::explain::ExplainReport;
use super::plot::{missed, plan_file};
use crate::error::CliError;
use crate::output;

/// Arguments of `a2ml report`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  a2ml report examples/push_box_aside_coman.a2ml -o push_box.html

The page needs no network: styles, pictures and the playback script are
inline. Exit codes as `a2ml plot`.")]
pub struct ReportArgs {
    /// The task file (it is planned first).
    #[arg(value_name = "TASK.a2ml")]
    pub file: PathBuf,
    /// The HTML file to write.
    #[arg(short = 'o', long = "output", value_name = "OUT.html")]
    pub output: PathBuf,
    /// Seed of the randomised solvers, overriding the task's `settings { seed }`.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
}

/// Runs `a2ml report`.
///
/// # Errors
/// As `a2ml plot`.
pub fn run(args: &ReportArgs) -> Result<(), CliError> {
    super::plan::check_folder(&args.output)?;
    let planned = plan_file(&args.file, args.seed)?;
    let decomposition =
        decompose::decompose(&planned.robot, &planned.task, &DecomposeOptions::default())
            .map_err(|e| CliError::Input(format!("{}: {e}", args.file.display())))?;
    let explained =
        ExplainReport::new(&args.file, &planned.robot, &planned.task, &decomposition).to_text();
    let input = ReportInput {
        robot: &planned.robot,
        task: &planned.task,
        source: &planned.source,
        plan: &planned.plan,
        decomposition: Some(&explained),
    };
    write_report(&args.output, &input).map_err(|e| CliError::Io(e.to_string()))?;
    output::print(&format!("wrote  {}\n", args.output.display()))?;
    missed(&planned.plan, "the report")
}
