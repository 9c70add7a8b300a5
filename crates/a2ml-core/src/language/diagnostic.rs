//! Located messages about a task file: a byte span and words a person can
//! act on, rendered as `file:line:col`, the source line and a caret.

use super::ast::Span;

/// One problem in a task file.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Diagnostic {
    /// Where.
    pub span: Span,
    /// What is wrong or what was expected.
    pub message: String,
    /// A suggestion, e.g. "did you mean `θsw`?".
    pub help: Option<String>,
}

impl Diagnostic {
    /// A diagnostic without help.
    pub fn new(span: Span, message: impl Into<String>) -> Self {
        Self { span, message: message.into(), help: None }
    }

    /// Adds a suggestion.
    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }
}

/// Every problem found in one file, with the text they point into.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostics {
    /// The file, if the text came from one.
    pub path: Option<String>,
    /// The source text.
    pub source: String,
    /// The problems, in source order.
    pub items: Vec<Diagnostic>,
    /// Problems found after the first [`crate::language::Limits::max_errors`], not kept.
    pub omitted: usize,
}

/// Characters of a source line shown on each side of a caret: a long line is cut to a
/// window around it, so that rendering costs the same for any line length.
const CONTEXT: usize = 60;

impl Diagnostics {
    /// Line and column (1-based, in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let lines = LineIndex::new(&self.source);
        let (line, line_start) = lines.locate(floor_boundary(&self.source, offset));
        (line, self.source[line_start..floor_boundary(&self.source, offset)].chars().count() + 1)
    }

    /// One diagnostic, rendered with its location, source line and caret.
    pub fn render(&self, d: &Diagnostic) -> String {
        self.render_with(&LineIndex::new(&self.source), d)
    }

    /// [`Diagnostics::render`] with the line starts found once for every diagnostic.
    fn render_with(&self, lines: &LineIndex, d: &Diagnostic) -> String {
        let source = self.source.as_str();
        let path = self.path.as_deref().unwrap_or("<input>");
        let start = floor_boundary(source, d.span.start);
        let (line, line_start) = lines.locate(start);
        let line_end = lines.end_of(line, source.len());
        let end = floor_boundary(source, d.span.end.clamp(start, line_end));
        let col = source[line_start..start].chars().count() + 1;
        // The shown part of the line: up to CONTEXT characters each side of the caret.
        let before: Vec<(usize, char)> = source[line_start..start].char_indices().collect();
        let (shown_start, cut_before) = match before.len().checked_sub(CONTEXT) {
            Some(k) if k > 0 => (line_start + before[k].0, true),
            _ => (line_start, false),
        };
        // The caret covers the span on this line, at most 2 CONTEXT characters of it.
        let caret_end =
            source[start..end].char_indices().nth(2 * CONTEXT).map_or(end, |(i, _)| start + i);
        let caret = source[start..caret_end].chars().count().max(1);
        let shown_end = source[caret_end..line_end]
            .char_indices()
            .nth(CONTEXT)
            .map_or(line_end, |(i, _)| caret_end + i);
        let text = source[shown_start..shown_end].trim_end_matches('\r');
        let (lead, tail) =
            (if cut_before { "…" } else { "" }, if shown_end < line_end { "…" } else { "" });
        let pad = source[shown_start..start].chars().count() + usize::from(cut_before);
        let gutter = " ".repeat(line.to_string().len());
        let mut out = format!(
            "error: {}\n{gutter}--> {path}:{line}:{col}\n{gutter} |\n{line} | {lead}{text}{tail}\n{gutter} | {}{}",
            d.message,
            " ".repeat(pad),
            "^".repeat(caret)
        );
        if let Some(help) = &d.help {
            out += &format!("\n{gutter} = help: {help}");
        }
        out
    }
}

/// The byte offset of every line's start, found once, so that locating a diagnostic is a
/// binary search rather than a scan from the file's start.
struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    fn new(source: &str) -> Self {
        let newlines = source.match_indices('\n').map(|(i, _)| i + 1);
        Self { starts: std::iter::once(0).chain(newlines).collect() }
    }

    /// The 1-based line holding `offset` and the byte offset of its start.
    fn locate(&self, offset: usize) -> (usize, usize) {
        let k = self.starts.partition_point(|&s| s <= offset).saturating_sub(1);
        (k + 1, self.starts[k])
    }

    /// The byte offset of the end of 1-based `line`, before its line break.
    fn end_of(&self, line: usize, len: usize) -> usize {
        self.starts.get(line).map_or(len, |next| next - 1)
    }
}

fn floor_boundary(s: &str, i: usize) -> usize {
    let mut i = i.min(s.len());
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

impl std::fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let lines = LineIndex::new(&self.source);
        for (k, d) in self.items.iter().enumerate() {
            if k > 0 {
                f.write_str("\n\n")?;
            }
            f.write_str(&self.render_with(&lines, d))?;
        }
        let total = self.items.len() + self.omitted;
        if self.omitted > 0 {
            write!(
                f,
                "\n\n{total} errors, the first {} shown (raise the limit with --max-errors)",
                self.items.len()
            )?;
        } else if total > 1 {
            write!(f, "\n\n{total} errors")?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostics {}
