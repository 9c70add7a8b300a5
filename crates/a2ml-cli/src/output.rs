//! Helpers the commands share for presenting results: conversions to plain
//! arrays for JSON, number formatting and aligned plain-text tables,
//! writing to stdout and stderr, and the checks on output paths.
//!
//! Vectors are `[x, y, z]`, quaternions `[w, x, y, z]` with w ≥ 0.

use std::io::Write;
use std::path::Path;

use a2ml_core::math::{Real, Rotation3, UnitQuaternion, Vector3};

use crate::error::CliError;

/// Decimals for lengths (m) and angles in radians.
pub const FINE: usize = 4;
/// Decimals for angles in degrees.
pub const COARSE: usize = 2;

/// `x` with a negative zero made positive, so no output shows `-0`.
pub fn unsigned_zero(x: Real) -> Real {
    x + 0.0
}

/// A vector as `[x, y, z]`.
pub fn vec3(v: &Vector3) -> [Real; 3] {
    [v.x, v.y, v.z].map(unsigned_zero)
}

/// A rotation as a unit quaternion `[w, x, y, z]`, sign chosen so that w ≥ 0.
pub fn quaternion(r: &Rotation3) -> [Real; 4] {
    let q = UnitQuaternion::from_rotation_matrix(r);
    let c = q.quaternion().coords; // stored as [x, y, z, w]
    let sign = if c[3] < 0.0 { -1.0 } else { 1.0 };
    [c[3], c[0], c[1], c[2]].map(|v| unsigned_zero(sign * v))
}

/// Radians to degrees.
pub fn deg(rad: Real) -> Real {
    rad.to_degrees()
}

/// `x` with `decimals` decimals, never printed as `-0.000`.
pub fn num(x: Real, decimals: usize) -> String {
    let text = format!("{x:.decimals$}");
    if text.starts_with('-') && text[1..].chars().all(|c| c == '0' || c == '.') {
        text[1..].to_owned()
    } else {
        text
    }
}

/// Every value of `values` through [`num`].
pub fn nums(values: &[Real], decimals: usize) -> Vec<String> {
    values.iter().map(|&v| num(v, decimals)).collect()
}

/// `yes` or `no`.
pub fn yes_no(b: bool) -> String {
    (if b { "yes" } else { "no" }).to_owned()
}

/// One line of a [`Table`].
enum Row {
    /// A label and values, aligned in columns.
    Cells(Vec<String>),
    /// A label and free text that takes no part in the column widths.
    Note(String, String),
    /// A section title: unindented, after a blank line.
    Title(String),
    /// Indented free text.
    Line(String),
}

/// A plain-text table: the leading columns left-aligned (one unless told),
/// and any others marked so, the rest right-aligned; columns two spaces
/// apart, every line but the titles indented by two spaces. Titles let
/// several sections share columns.
pub struct Table {
    header: Option<Vec<String>>,
    left: usize,
    also_left: Vec<usize>,
    rows: Vec<Row>,
}

impl Default for Table {
    fn default() -> Self {
        Self { header: None, left: 1, also_left: Vec::new(), rows: Vec::new() }
    }
}

impl Table {
    /// An empty table without a header.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty table with a header row.
    pub fn with_header<S: Into<String>>(header: impl IntoIterator<Item = S>) -> Self {
        Self { header: Some(header.into_iter().map(Into::into).collect()), ..Self::default() }
    }

    /// Left-aligns the first `n` columns instead of only the first.
    pub fn left_columns(mut self, n: usize) -> Self {
        self.left = n;
        self
    }

    /// Left-aligns these columns (0-based) too: text among numbers.
    pub fn left_aligned(mut self, columns: impl IntoIterator<Item = usize>) -> Self {
        self.also_left.extend(columns);
        self
    }

    /// Adds a line of free text.
    pub fn line(&mut self, text: impl Into<String>) {
        self.rows.push(Row::Line(text.into()));
    }

    /// Adds a section title.
    pub fn title(&mut self, text: impl Into<String>) {
        self.rows.push(Row::Title(text.into()));
    }

    /// Adds a row: a label then values.
    pub fn row(&mut self, label: impl Into<String>, values: impl IntoIterator<Item = String>) {
        let mut cells = vec![label.into()];
        cells.extend(values);
        self.rows.push(Row::Cells(cells));
    }

    /// Adds a label followed by free text (a message rather than values).
    pub fn note(&mut self, label: impl Into<String>, text: impl Into<String>) {
        self.rows.push(Row::Note(label.into(), text.into()));
    }

    /// Appends the table to `out`.
    pub fn render(&self, out: &mut String) {
        let cell_rows = self.header.iter().chain(self.rows.iter().filter_map(|r| match r {
            Row::Cells(cells) => Some(cells),
            Row::Note(..) | Row::Title(_) | Row::Line(_) => None,
        }));
        let mut widths: Vec<usize> = Vec::new();
        for cells in cell_rows {
            for (i, cell) in cells.iter().enumerate() {
                let w = cell.chars().count();
                match widths.get_mut(i) {
                    Some(width) => *width = (*width).max(w),
                    None => widths.push(w),
                }
            }
        }
        for row in &self.rows {
            if let Row::Note(label, _) = row {
                let w = label.chars().count();
                match widths.first_mut() {
                    Some(width) => *width = (*width).max(w),
                    None => widths.push(w),
                }
            }
        }
        let line = |cells: &[String], out: &mut String| {
            let mut text = String::from("  ");
            for (i, cell) in cells.iter().enumerate() {
                let pad = " ".repeat(widths[i].saturating_sub(cell.chars().count()));
                if i > 0 {
                    text.push_str("  ");
                }
                if i < self.left || self.also_left.contains(&i) {
                    text.push_str(cell);
                    text.push_str(&pad);
                } else {
                    text.push_str(&pad);
                    text.push_str(cell);
                }
            }
            out.push_str(text.trim_end());
            out.push('\n');
        };
        // The header goes right above the first row of values: after a
        // leading title, and not at all when there are no values.
        let mut header = self.header.as_ref();
        for row in &self.rows {
            match row {
                Row::Cells(cells) => {
                    if let Some(header) = header.take() {
                        line(header, out);
                    }
                    line(cells, out);
                }
                Row::Note(label, text) => {
                    let pad = widths[0].saturating_sub(label.chars().count());
                    out.push_str(&format!("  {label}{}  {text}\n", " ".repeat(pad)));
                }
                Row::Line(text) => {
                    out.push_str("  ");
                    out.push_str(text);
                    out.push('\n');
                }
                Row::Title(text) => {
                    if !out.is_empty() {
                        out.push('\n');
                    }
                    out.push_str(text);
                    out.push('\n');
                }
            }
        }
    }
}

/// Writes `text` to stdout. A closed pipe (`a2ml … | head`) is not an error.
///
/// # Errors
/// [`CliError::Io`] when stdout cannot be written for another reason.
pub fn print(text: &str) -> Result<(), CliError> {
    let mut stdout = std::io::stdout().lock();
    match stdout.write_all(text.as_bytes()).and_then(|()| stdout.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(CliError::Io(format!("cannot write to stdout: {e}")))
        }
        _ => Ok(()),
    }
}

/// Prints a report as pretty JSON (its warnings inside it), or as text with
/// its warnings on stderr first.
///
/// # Errors
/// [`CliError::Io`] when stdout cannot be written.
pub fn emit<R: serde::Serialize>(
    report: &R,
    json: bool,
    warnings: &[String],
    text: impl FnOnce() -> String,
) -> Result<(), CliError> {
    if json {
        let json = serde_json::to_string_pretty(report)
            .map_err(|e| CliError::Io(format!("cannot write JSON: {e}")))?;
        print(&(json + "\n"))
    } else {
        for warning in warnings {
            warn(warning);
        }
        print(&text())
    }
}

/// `n noun` or `n nouns`.
pub fn count(n: usize, noun: &str) -> String {
    if n == 1 { format!("1 {noun}") } else { format!("{n} {noun}s") }
}

/// Writes a report (e.g. rendered diagnostics) and a line break to stderr.
pub fn report(text: &str) {
    let _ = writeln!(std::io::stderr(), "{text}");
}

/// Writes `warning: <message>` to stderr.
pub fn warn(message: &str) {
    let _ = writeln!(std::io::stderr(), "warning: {message}");
}

/// Refuses, before any work, an output path that is not a regular file (a folder, device,
/// FIFO, socket or symbolic link) or whose folder does not exist.
///
/// # Errors
/// [`CliError::Input`] for a path that is not a regular file, [`CliError::Io`] for a missing
/// folder or a path that cannot be examined.
pub fn check_output(path: &Path) -> Result<(), CliError> {
    match a2ml_core::output::refused_kind(path) {
        Ok(Some(kind)) => {
            return Err(CliError::Input(format!(
                "cannot write {}: it is {kind}, and outputs replace only regular files",
                path.display()
            )));
        }
        Ok(None) => {}
        Err(e) => return Err(CliError::Io(e.to_string())),
    }
    match path.parent() {
        Some(folder) if !folder.as_os_str().is_empty() && !folder.is_dir() => Err(CliError::Io(
            format!("cannot write {}: there is no folder {}", path.display(), folder.display()),
        )),
        _ => Ok(()),
    }
}

/// Refuses an output path that is the same file as one of the run's inputs (same device and
/// inode, links resolved), which writing the output would destroy.
///
/// # Errors
/// [`CliError::Input`] naming the output and the input.
pub fn check_not_an_input(output: &Path, inputs: &[&Path]) -> Result<(), CliError> {
    let Ok(written) = std::fs::metadata(output) else { return Ok(()) };
    for input in inputs {
        if std::fs::metadata(input).is_ok_and(|read| same_file(&written, &read)) {
            return Err(CliError::Input(format!(
                "cannot write {}: it is the input {}",
                output.display(),
                input.display()
            )));
        }
    }
    Ok(())
}

#[cfg(unix)]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

#[cfg(not(unix))]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    // Without inode numbers: the same size and modification time is the best available.
    a.len() == b.len() && a.modified().ok() == b.modified().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_negative_zero() {
        assert_eq!(num(-1e-9, 4), "0.0000");
        assert_eq!(num(-0.5, 2), "-0.50");
        assert_eq!(unsigned_zero(-0.0).to_string(), "0");
    }

    #[test]
    fn columns_align() {
        let mut t = Table::with_header(["name", "value"]);
        t.row("a", ["1.00".to_owned()]);
        t.row("long name", ["-10.00".to_owned()]);
        t.note("why", "a long message that does not widen the columns");
        let mut out = String::new();
        t.render(&mut out);
        let lines: Vec<&str> = out.lines().collect();
        assert_eq!(lines[0], "  name        value");
        assert_eq!(lines[1], "  a            1.00");
        assert_eq!(lines[2], "  long name  -10.00");
        assert!(lines[3].starts_with("  why        a long"));
    }
}
