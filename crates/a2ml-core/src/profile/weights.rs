//! Weights of the task components in the velocity QP (paper eq. 7, docs/design.md §5).

use crate::math::{PI, Real};

/// The weights of the QP's task components.
///
/// Goal components are weighted `goal_end` at the start and end of a segment and `goal_middle`
/// halfway, so the arm may leave the reference path in the middle and must reach the goal at
/// the end; path components are weighted `path` throughout, holds included.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct WeightOptions {
    /// Goal weight at t = 0 and t = T (default 1).
    pub goal_end: Real,
    /// Goal weight at t = T/2 (default 0.1).
    pub goal_middle: Real,
    /// Path weight (default 10).
    pub path: Real,
}

impl Default for WeightOptions {
    fn default() -> Self {
        Self { goal_end: 1.0, goal_middle: 0.1, path: 10.0 }
    }
}

/// Whether a component follows a goal primitive or a path primitive (hold is a path).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Role {
    /// MP^g: weight from the goal schedule.
    Goal,
    /// MP^p, hold included: constant weight.
    Path,
}

/// The weight schedule of one segment of duration T (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeightSchedule {
    duration: Real,
    options: WeightOptions,
}

impl WeightSchedule {
    /// The schedule over a segment of `duration` (s). A duration that is not positive and
    /// finite gives the end weight throughout.
    pub fn new(duration: Real, options: WeightOptions) -> Self {
        Self { duration, options }
    }

    /// The segment duration T (s).
    pub fn duration(&self) -> Real {
        self.duration
    }

    /// The options.
    pub fn options(&self) -> &WeightOptions {
        &self.options
    }

    /// The goal weight at t (s, clamped to [0, T]):
    /// w(t) = w_end - (w_end - w_middle) sin²(π t/T), smooth, with zero slope at both ends
    /// and at the middle.
    #[inline]
    pub fn goal(&self, t: Real) -> Real {
        let WeightOptions { goal_end, goal_middle, .. } = self.options;
        if !(self.duration.is_finite() && self.duration > 0.0) {
            return goal_end;
        }
        let tau = (t / self.duration).clamp(0.0, 1.0);
        let s = (PI * tau).sin();
        goal_end - (goal_end - goal_middle) * s * s
    }

    /// The path weight (constant).
    #[inline]
    pub fn path(&self) -> Real {
        self.options.path
    }

    /// The weight of a component with `role` at t (s).
    #[inline]
    pub fn weight(&self, role: Role, t: Real) -> Real {
        match role {
            Role::Goal => self.goal(t),
            Role::Path => self.path(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_go_one_tenth_one() {
        let w = WeightSchedule::new(2.0, WeightOptions::default());
        assert_eq!(w.goal(0.0), 1.0);
        assert!((w.goal(2.0) - 1.0).abs() < 1e-15);
        assert!((w.goal(1.0) - 0.1).abs() < 1e-15);
        assert_eq!(w.weight(Role::Path, 0.7), 10.0);
        assert_eq!(w.goal(-3.0), 1.0);
    }

    #[test]
    fn degenerate_duration_gives_end_weight() {
        for d in [0.0, -1.0, Real::NAN] {
            assert_eq!(WeightSchedule::new(d, WeightOptions::default()).goal(0.3), 1.0);
        }
    }
}
