//! `a2ml fmt`: a task file in canonical form ([`language::format`]), comments
//! kept: printed, checked (`--check`) or written back (`--write`). Only the
//! syntax matters here, so a file whose robot is missing still formats.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use clap::Args;

use a2ml_core::language;

use crate::error::{CliError, FileTally};
use crate::output;

/// Arguments of `a2ml fmt`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  a2ml fmt task.a2ml
  a2ml fmt --check examples/*.a2ml
  a2ml fmt --write task.a2ml

Comments are kept, each beside the line of the node it was written with.

Exit codes: 0 success, 1 a file cannot be read or written, 2 a syntax error
or (with --check) a file not in canonical form (1 wins when both happen).")]
pub struct FmtArgs {
    /// The task files (one, unless --check or --write).
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// Print nothing and change nothing; exit 2, naming each file, when a
    /// file is not in canonical form.
    #[arg(long, conflicts_with = "write")]
    pub check: bool,
    /// Rewrite each file in canonical form instead of printing it; a file
    /// already canonical is left untouched.
    #[arg(long)]
    pub write: bool,
}

/// Runs `a2ml fmt`: every file is handled and reported, whatever the others do.
///
/// # Errors
/// [`CliError::Io`] when a file cannot be read or written, else
/// [`CliError::Input`] for a syntax error, a file not in canonical form
/// under `--check`, or several files to print.
pub fn run(args: &FmtArgs) -> Result<(), CliError> {
    if !args.check && !args.write && args.files.len() > 1 {
        return Err(CliError::Input(
            "fmt prints one file; use --check or --write for several".to_owned(),
        ));
    }
    let mut tally = FileTally::default();
    for path in &args.files {
        tally.files += 1;
        let text = match language::read_source(path, &language::Limits::default()) {
            Ok(text) => text,
            Err(e) => {
                output::report(&format!("error: cannot read {}: {e}", path.display()));
                tally.unreadable += 1;
                continue;
            }
        };
        let tree = match language::parse_ast(&text, Some(path)) {
            Ok(tree) => tree,
            Err(diagnostics) => {
                output::report(&format!("{diagnostics}\n"));
                tally.invalid += 1;
                continue;
            }
        };
        let canonical = language::format(&tree);
        if args.check {
            if canonical != text {
                output::report(&format!(
                    "error: {0}: not in canonical form (`a2ml fmt --write {0}` rewrites it)",
                    path.display()
                ));
                tally.not_canonical += 1;
            }
        } else if args.write {
            if canonical != text {
                if let Err(error) = write_in_place(path, &canonical) {
                    output::report(&format!("error: {error}"));
                    tally.unwritable += 1;
                }
            }
        } else {
            output::print(&canonical)?;
        }
    }
    tally.finish(if args.check { "failed the check" } else { "could not be formatted" })
}

/// Replaces the file (the target, if `path` is a symbolic link) with `text`
/// through a temporary file in the same folder, renamed over it, so that
/// the file is never half written. Its permissions are kept.
///
/// # Errors
/// A message naming `path` and the OS error.
fn write_in_place(path: &Path, text: &str) -> Result<(), String> {
    let fail = |e: std::io::Error| format!("cannot write {}: {e}", path.display());
    let target = fs::canonicalize(path).map_err(fail)?;
    let permissions = fs::metadata(&target).map_err(fail)?.permissions();
    let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let temporary = target.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
    let written = fs::File::create(&temporary)
        .and_then(|mut file| {
            file.write_all(text.as_bytes())?;
            file.sync_all()?;
            file.set_permissions(permissions)
        })
        .and_then(|()| fs::rename(&temporary, &target));
    if written.is_err() {
        // Nothing to do if the leftover cannot be removed either.
        let _ = fs::remove_file(&temporary);
    }
    written.map_err(fail)
}
