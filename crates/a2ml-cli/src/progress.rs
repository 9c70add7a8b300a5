//! The progress bar of `a2ml plan`, fed by the core's progress reports (which come from
//! inside the QP and RRT loops, so the bar moves within a long segment). Drawn with
//! indicatif on stderr only when stderr is a terminal and planning has taken a moment:
//! piped or redirected output never holds its escape codes.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use a2ml_core::solve::Progress;

/// Planning shorter than this shows no bar: it would only flicker.
const DELAY: Duration = Duration::from_millis(300);

/// Steps of the bar: fine enough to move within a segment, coarse enough that a
/// report changes it rarely.
const STEPS: u64 = 1000;

/// The bar of one `plan` run.
pub struct PlanBar {
    started: Instant,
    /// None when stderr is not a terminal: nothing is ever drawn.
    bar: Option<ProgressBar>,
    shown: bool,
}

impl PlanBar {
    /// A bar for planning that started at `started`; hidden unless stderr is a terminal.
    pub fn new(started: Instant) -> Self {
        Self { started, bar: std::io::stderr().is_terminal().then(bar), shown: false }
    }

    /// Shows where planning is: segments done, the action, the share of the whole.
    pub fn update(&mut self, progress: &Progress) {
        let Some(bar) = &self.bar else { return };
        if progress.total == 0 || self.started.elapsed() < DELAY {
            return;
        }
        if !self.shown {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            self.shown = true;
        }
        // Whole steps of the share done; the share is in [0, 1].
        let position = (progress.overall().clamp(0.0, 1.0) * STEPS as f64).round() as u64;
        bar.set_position(position);
        bar.set_message(format!(
            "{}/{} segments, `{}` segment {}",
            progress.done.min(progress.total),
            progress.total,
            progress.action,
            progress.segment + 1
        ));
    }

    /// Erases the bar, so that what follows starts on a clean line.
    pub fn clear(&mut self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// A bar that draws nothing until [`PlanBar::update`] gives it stderr.
fn bar() -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(STEPS), ProgressDrawTarget::hidden());
    let style = ProgressStyle::with_template("planning [{bar:24}] {percent:>3}% {msg}")
        .map(|style| style.progress_chars("#>-"))
        .unwrap_or_else(|_| ProgressStyle::default_bar());
    bar.set_style(style);
    bar
}
