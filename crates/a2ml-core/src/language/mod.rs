//! The A2ML task language: text -> syntax tree ([`ast`]) -> validated
//! [`Task`], with located diagnostics.
//!
//! Entry points: [`parse`] (text), [`load`] (a file), [`parse_ast`] (the
//! syntax tree alone, comments included), [`format()`] (a syntax tree back
//! to canonical text, comments kept), [`with_goal`] (a task's text with new
//! goal values). Units become SI at validation; every
//! syntax node keeps the byte span of its text.

pub mod ast;
mod bounds;
mod diagnostic;
pub mod display;
mod edit;
mod format;
mod syntax;
mod task;
mod validate;
mod variable;
pub use variable::Measure;

use std::path::Path;

pub use bounds::{Limits, MAX_ANGLE, MAX_LENGTH, ReadError, read_source, samples};
pub use diagnostic::{Diagnostic, Diagnostics};
pub use edit::{EditError, with_goal};
pub use format::{WIDTH, format};
pub use task::*;

/// Why a task file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum LanguageError {
    /// The file cannot be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// The path as given.
        path: String,
        /// The OS message.
        message: String,
    },
    /// The text is not a valid task.
    #[error("{0}")]
    Invalid(Diagnostics),
}

fn diagnostics(text: &str, path: Option<&Path>, items: Vec<Diagnostic>) -> Diagnostics {
    Diagnostics {
        path: path.map(|p| p.display().to_string()),
        source: text.to_owned(),
        items,
        omitted: 0,
    }
}

/// Parses text into its syntax tree (no validation).
///
/// # Errors
/// The syntax error, located.
pub fn parse_ast(text: &str, path: Option<&Path>) -> Result<ast::File, Diagnostics> {
    syntax::parse_file(text).map_err(|d| diagnostics(text, path, vec![d]))
}

/// Parses and validates a task; `path` names the file in messages and
/// anchors the robot path.
///
/// # Errors
/// Every problem found, located.
pub fn parse(text: &str, path: Option<&Path>) -> Result<Task, Diagnostics> {
    parse_with(text, path, &Limits::default())
}

/// [`parse`] within `limits`: what the task may ask for, and how many errors are reported
/// (the rest are counted in [`Diagnostics::omitted`]).
///
/// # Errors
/// Every problem found, located, up to `limits.max_errors`.
pub fn parse_with(text: &str, path: Option<&Path>, limits: &Limits) -> Result<Task, Diagnostics> {
    let file = parse_ast(text, path)?;
    let base_dir = path.map(|p| p.parent().unwrap_or(Path::new("")));
    validate::validate(&file, text, base_dir, limits).map_err(|mut items| {
        let omitted = bounds::keep_first_errors(&mut items, limits);
        Diagnostics { omitted, ..diagnostics(text, path, items) }
    })
}

/// Reads, parses and validates a task file.
///
/// # Errors
/// [`LanguageError::Io`] or every problem found.
pub fn load(path: impl AsRef<Path>) -> Result<Task, LanguageError> {
    load_with(path, &Limits::default())
}

/// [`load`] within `limits` ([`parse_with`]; at most `limits.max_input_bytes` are read).
///
/// # Errors
/// As [`load`].
pub fn load_with(path: impl AsRef<Path>, limits: &Limits) -> Result<Task, LanguageError> {
    let path = path.as_ref();
    let text = read_source(path, limits).map_err(|e| LanguageError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    parse_with(&text, Some(path), limits).map_err(LanguageError::Invalid)
}
