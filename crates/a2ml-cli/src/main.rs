//! The `a2ml` command line: parses the arguments, runs the subcommand and
//! turns the outcome into an exit code (0 success, 1 I/O error, 2 invalid
//! input, 3 a goal missed, 4 planning failed; see [`error::CliError`]; 128 +
//! the signal's number when interrupted, see [`signals`]).
//! Everything else lives in [`commands`] and the core library.

// The arguments' doc comments are clap's help text, where `<FILE>` is a placeholder the
// user reads, not an HTML tag.
#![allow(rustdoc::invalid_html_tags)]

mod args;
mod batch;
mod commands;
mod error;
mod output;
mod progress;
mod signals;

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    // clap prints its own usage errors and exits with code 2.
    let cli = args::Cli::parse();
    let result =
        signals::Temporaries::install().and_then(|temporaries| commands::run(cli, &temporaries));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            // Nothing sensible is left to do if stderr itself is closed.
            let _ = writeln!(std::io::stderr(), "error: {error}");
            error.exit_code()
        }
    }
}
