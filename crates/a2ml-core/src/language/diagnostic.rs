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
}

impl Diagnostics {
    /// Line and column (1-based, in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.source.len());
        let before = &self.source[..floor_boundary(&self.source, offset)];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        (line, before[line_start..].chars().count() + 1)
    }

    /// One diagnostic, rendered with its location, source line and caret.
    pub fn render(&self, d: &Diagnostic) -> String {
        let (line, col) = self.line_col(d.span.start);
        let path = self.path.as_deref().unwrap_or("<input>");
        let start = floor_boundary(&self.source, d.span.start.min(self.source.len()));
        let line_start = self.source[..start].rfind('\n').map_or(0, |i| i + 1);
        let line_end = self.source[start..].find('\n').map_or(self.source.len(), |i| start + i);
        let text = self.source[line_start..line_end].trim_end_matches('\r');
        let end = floor_boundary(&self.source, d.span.end.clamp(start, line_end));
        let pad = self.source[line_start..start].chars().count();
        let width = self.source[start..end].chars().count().max(1);
        let gutter = " ".repeat(line.to_string().len());
        let mut out = format!(
            "error: {}\n{gutter}--> {path}:{line}:{col}\n{gutter} |\n{line} | {text}\n{gutter} | {}{}",
            d.message,
            " ".repeat(pad),
            "^".repeat(width)
        );
        if let Some(help) = &d.help {
            out += &format!("\n{gutter} = help: {help}");
        }
        out
    }
}

fn floor_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

impl std::fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let rendered: Vec<String> = self.items.iter().map(|d| self.render(d)).collect();
        write!(f, "{}", rendered.join("\n\n"))?;
        if self.items.len() > 1 {
            write!(f, "\n\n{} errors", self.items.len())?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostics {}
