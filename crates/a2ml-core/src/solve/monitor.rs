//! What the solvers' long loops tell their caller and ask of it: how far a segment has got
//! (for progress displays) and whether the wall-clock limit the user set has passed. Without a
//! limit nothing a solver decides depends on the clock, so the same task and seed give the
//! same plan on any machine.

use std::time::{Duration, Instant};

use crate::math::Real;

/// A solver loop's link to its caller: a progress callback and an optional deadline.
pub struct Monitor<'a> {
    deadline: Option<Instant>,
    report: Option<&'a mut dyn FnMut(Real)>,
}

impl<'a> Monitor<'a> {
    /// Reports to `report` (the fraction of the segment done, in [0, 1]) and stops at
    /// `deadline`, if any.
    pub fn new(deadline: Option<Instant>, report: &'a mut dyn FnMut(Real)) -> Self {
        Self { deadline, report: Some(report) }
    }

    /// No report and no deadline.
    pub fn silent() -> Monitor<'static> {
        Monitor { deadline: None, report: None }
    }

    /// The same monitor with the earlier of its deadline and `seconds` from now, if given.
    pub fn within(&mut self, seconds: Option<Real>) -> Monitor<'_> {
        let own = seconds.and_then(deadline_after);
        let deadline = match (self.deadline, own) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        Monitor { deadline, report: self.report.as_deref_mut().map(|r| r as &mut dyn FnMut(Real)) }
    }

    /// Tells the caller that `fraction` (clamped to [0, 1]) of the segment is done.
    pub fn report(&mut self, fraction: Real) {
        if let Some(report) = self.report.as_deref_mut() {
            report(fraction.clamp(0.0, 1.0));
        }
    }

    /// Whether the deadline has passed (never, without one).
    pub fn expired(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d)
    }
}

/// The instant `seconds` from now; `None` for a limit that is not positive and finite.
pub fn deadline_after(seconds: Real) -> Option<Instant> {
    (seconds.is_finite() && seconds > 0.0)
        .then(|| Instant::now() + Duration::from_secs_f64(seconds.min(1e9)))
}
