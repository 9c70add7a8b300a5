//! The reference of an angle, θsw or θe: a signed change, or a hold; θsw wraps.

use super::finite_scalar;
use crate::math::{Real, wrap_angle};
use crate::profile::{BellProfile, ProfileError};

/// The reference of an angle θsw or θe (rad): a signed change with a bell speed, or a hold.
///
/// A periodic angle (θsw) is reported wrapped into (-π, π], and its goal is reached the
/// shorter way round; θe is not wrapped and a goal is reached by the plain difference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleReference {
    start: Real,
    /// +1 or -1: the sign of the change.
    direction: Real,
    bell: BellProfile,
    periodic: bool,
}

impl AngleReference {
    /// The angle kept at `start` (rad) for `duration` (s).
    ///
    /// # Errors
    /// Non-finite start or invalid duration.
    pub fn hold(start: Real, periodic: bool, duration: Real) -> Result<Self, ProfileError> {
        Self::by(start, 0.0, periodic, duration)
    }

    /// The angle changing from `start` by the signed `change` (rad): the feature `by S`.
    ///
    /// # Errors
    /// Non-finite inputs or an invalid duration.
    pub fn by(
        start: Real,
        change: Real,
        periodic: bool,
        duration: Real,
    ) -> Result<Self, ProfileError> {
        finite_scalar(start, "start angle")?;
        finite_scalar(change, "angle change")?;
        let start = if periodic { wrap_angle(start) } else { start };
        let direction = if change < 0.0 { -1.0 } else { 1.0 };
        Ok(Self { start, direction, bell: BellProfile::new(duration, change.abs())?, periodic })
    }

    /// The angle from `start` to `goal` (rad): the shortest signed angle when periodic
    /// (wrap_angle(goal - start)), the plain difference otherwise.
    ///
    /// # Errors
    /// Non-finite inputs or an invalid duration.
    pub fn goal(
        start: Real,
        goal: Real,
        periodic: bool,
        duration: Real,
    ) -> Result<Self, ProfileError> {
        finite_scalar(goal, "goal angle")?;
        let change = if periodic { wrap_angle(goal - start) } else { goal - start };
        Self::by(start, change, periodic, duration)
    }

    /// The angle at t = 0 (rad; wrapped when periodic).
    pub fn start(&self) -> Real {
        self.start
    }

    /// The signed change over the whole primitive (rad).
    pub fn change(&self) -> Real {
        self.direction * self.bell.distance()
    }

    /// Whether the angle is wrapped into (-π, π].
    pub fn is_periodic(&self) -> bool {
        self.periodic
    }

    /// The speed profile (distance |change| in rad).
    pub fn bell(&self) -> &BellProfile {
        &self.bell
    }

    /// The angle at t = T (rad).
    pub fn end(&self) -> Real {
        self.sample(self.bell.duration()).0
    }

    /// The angle (rad) and its rate (rad/s) at t (s), clamped to [0, T].
    pub fn sample(&self, t: Real) -> (Real, Real) {
        (self.at_distance(self.bell.progress(t)), self.direction * self.bell.speed(t))
    }

    /// The change (rad) in the path's direction that reaches `angle`: the shorter way round,
    /// in (-π, π], when periodic.
    pub fn nearest_distance(&self, angle: Real) -> Real {
        let change = angle - self.start;
        self.direction * if self.periodic { wrap_angle(change) } else { change }
    }

    /// The angle (rad) after changing by `s` (rad) in the path's direction, not limited to the
    /// bell's distance.
    pub fn at_distance(&self, s: Real) -> Real {
        let value = self.start + self.direction * s;
        if self.periodic { wrap_angle(value) } else { value }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::PI;

    #[test]
    fn swivel_goal_takes_the_short_way_round() {
        let r = AngleReference::goal(3.0, -3.0, true, 1.0).expect("valid");
        assert!((r.change() - (2.0 * PI - 6.0)).abs() < 1e-15);
        assert!((wrap_angle(r.end() + 3.0)).abs() < 1e-12);
        // Wrapped throughout.
        for k in 0..=10 {
            let (v, _) = r.sample(k as Real / 10.0);
            assert!(v > -PI && v <= PI);
        }
        let e = AngleReference::goal(3.0, -3.0, false, 1.0).expect("valid");
        assert!((e.change() + 6.0).abs() < 1e-15);
    }
}
