//! What a task may ask for, checked at validation so that no input makes a2ml allocate or
//! compute without bound: [`Limits`] (samples, segments, errors reported, bytes read, each
//! with the CLI option that raises it) and the workspace bounds on lengths and angles, which
//! also keep every shape within sizes the collision queries handle.

use std::io::Read;
use std::path::Path;

use super::ast::Span;
use super::diagnostic::Diagnostic;
use crate::math::{PI, Real};

/// The largest length a task may give (m): coordinates, sizes, radii, path lengths. Far
/// beyond any arm's reach, far below where the collision queries lose their precision.
pub const MAX_LENGTH: Real = 100.0;

/// The largest angle a task may give (rad): a hundred turns.
pub const MAX_ANGLE: Real = 200.0 * PI;

/// How much one task may ask for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Most samples of the motion: its duration times the faster of the output and control
    /// rates (`--max-samples`), default 1,000,000.
    pub max_samples: u64,
    /// Most movement segments (`--max-segments`), default 10,000.
    pub max_segments: usize,
    /// Most errors reported per file; the rest are counted (`--max-errors`), default 100.
    pub max_errors: usize,
    /// Most bytes read from a task file (`--max-input-bytes`), default 64 MiB.
    pub max_input_bytes: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_samples: 1_000_000,
            max_segments: 10_000,
            max_errors: 100,
            max_input_bytes: 64 << 20,
        }
    }
}

/// Why [`read_source`] returned no text.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReadError {
    /// The OS refused, or the text is not UTF-8.
    #[error("{0}")]
    Io(String),
    /// The file goes on past the limit (a device or a pipe that never ends).
    #[error("it is larger than the limit of {limit} bytes (raise it with --max-input-bytes)")]
    TooLarge {
        /// [`Limits::max_input_bytes`].
        limit: u64,
    },
}

/// Reads a task file as UTF-8, at most `limits.max_input_bytes` of it: a device or a pipe
/// that never ends is refused at the limit.
///
/// # Errors
/// [`ReadError`].
pub fn read_source(path: &Path, limits: &Limits) -> Result<String, ReadError> {
    let io = |e: std::io::Error| ReadError::Io(e.to_string());
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(limits.max_input_bytes.saturating_add(1)).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > limits.max_input_bytes {
        return Err(ReadError::TooLarge { limit: limits.max_input_bytes });
    }
    String::from_utf8(bytes).map_err(|_| ReadError::Io("stream did not contain valid UTF-8".into()))
}

/// Samples a motion of `duration` s asks for at `rate` Hz (saturating, never NaN).
pub fn samples(duration: Real, rate: Real) -> u64 {
    let n = (duration * rate).ceil();
    if n.is_nan() || n < 0.0 {
        0
    } else if n >= u64::MAX as Real {
        u64::MAX
    } else {
        n as u64
    }
}

/// The written durations against [`Limits::max_samples`] at `rate`: an error at the
/// duration that takes the running total over the limit, or at the rate when one second
/// alone would.
pub(super) fn check_samples(
    durations: &[(Span, Real)],
    rate: (Span, Real),
    limits: &Limits,
) -> Option<Diagnostic> {
    let over = |n: u64| n > limits.max_samples;
    let message = |n: u64, what: String| {
        format!(
            "{what} asks for {} samples at {} Hz, more than the limit of {} (raise it with \
             --max-samples)",
            if n == u64::MAX { "more than 2^64".to_owned() } else { n.to_string() },
            short(rate.1),
            limits.max_samples
        )
    };
    if over(samples(1.0, rate.1)) {
        return Some(Diagnostic::new(rate.0, message(samples(1.0, rate.1), "one second".into())));
    }
    let mut total = 0.0;
    for (span, duration) in durations {
        total += duration;
        let n = samples(total, rate.1);
        if over(n) {
            let what = format!("a motion of {} s", short(total));
            return Some(Diagnostic::new(*span, message(n, what)));
        }
    }
    None
}

/// A number as written by a person: `250`, `1.5`, `1e19`.
fn short(x: Real) -> String {
    if x.abs() >= 1e6 { format!("{x:e}") } else { format!("{x}") }
}

/// Keeps the first `limits.max_errors` diagnostics; returns how many were left out.
pub(super) fn keep_first_errors(items: &mut Vec<Diagnostic>, limits: &Limits) -> usize {
    let omitted = items.len().saturating_sub(limits.max_errors);
    items.truncate(limits.max_errors);
    omitted
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_saturate() {
        assert_eq!(samples(2.0, 100.0), 200);
        assert_eq!(samples(1e308, 1e308), u64::MAX);
        assert_eq!(samples(Real::NAN, 1.0), 0);
    }

    #[test]
    fn the_sample_limit_is_met_at_the_duration_that_crosses_it() {
        let limits = Limits { max_samples: 1000, ..Limits::default() };
        let span = |k| Span { start: k, end: k + 1 };
        let rate = (span(0), 100.0);
        assert!(check_samples(&[(span(1), 5.0), (span(2), 5.0)], rate, &limits).is_none());
        let d = check_samples(&[(span(1), 5.0), (span(2), 6.0)], rate, &limits).expect("over");
        assert_eq!(d.span, span(2));
        assert!(d.message.contains("1100 samples") && d.message.contains("--max-samples"));
        let d = check_samples(&[], (span(0), 1e19), &limits).expect("over");
        assert_eq!(d.span, span(0));
    }
}
