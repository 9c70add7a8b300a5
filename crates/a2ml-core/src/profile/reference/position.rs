//! The reference of Pw: a line, a turn about an axis through S, a semi-elliptic arc, or a
//! hold.

use super::{finite_vector, signed_motion};
use crate::math::{PI, Real, Vector3, reject, rotation_about};
use crate::profile::{BellProfile, ProfileError, SemiEllipse};

/// The path of a wrist-position reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PositionPath {
    /// Pw stays at the start (distance 0).
    Hold,
    /// Pw moves along a straight line from the start; the distance (m) is the bell's.
    Line {
        /// Unit direction in {b}.
        direction: Vector3,
    },
    /// Pw turns about an axis through the shoulder S (the origin of {b}); the angle (rad) is
    /// the bell's distance.
    About {
        /// Unit axis in {b}.
        axis: Vector3,
    },
    /// Pw along a semi-ellipse from the start to the goal (`arc through`); the distance is
    /// its eccentric angle, π at the goal.
    Arc(SemiEllipse),
}

/// The reference of Pw (m, in {b}): a line, a rotation about an axis through S, a
/// semi-elliptic arc, or a hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionReference {
    start: Vector3,
    path: PositionPath,
    bell: BellProfile,
}

impl PositionReference {
    /// Pw kept at `start` for `duration` (s).
    ///
    /// # Errors
    /// Non-finite start or invalid duration.
    pub fn hold(start: Vector3, duration: Real) -> Result<Self, ProfileError> {
        finite_vector(&start, "start position")?;
        Ok(Self { start, path: PositionPath::Hold, bell: BellProfile::new(duration, 0.0)? })
    }

    /// Pw along the line from `start` in `direction` (normalised) for the signed `length` (m):
    /// the path feature `line d` with S = length.
    ///
    /// # Errors
    /// Non-finite inputs, a zero direction, or an invalid duration.
    pub fn line(
        start: Vector3,
        direction: &Vector3,
        length: Real,
        duration: Real,
    ) -> Result<Self, ProfileError> {
        finite_vector(&start, "start position")?;
        let (direction, bell) =
            signed_motion(direction, length, duration, ("line length", "line direction"))?;
        Ok(Self { start, path: PositionPath::Line { direction }, bell })
    }

    /// Pw from `start` to `goal` along the straight line (the goal primitive's shortest path);
    /// a hold when they coincide.
    ///
    /// # Errors
    /// Non-finite inputs or an invalid duration.
    pub fn goal(start: Vector3, goal: Vector3, duration: Real) -> Result<Self, ProfileError> {
        finite_vector(&start, "start position")?;
        finite_vector(&goal, "goal position")?;
        let delta = goal - start;
        let length = delta.norm();
        if length == 0.0 {
            return Self::hold(start, duration);
        }
        let bell = BellProfile::new(duration, length)?;
        Ok(Self { start, path: PositionPath::Line { direction: delta / length }, bell })
    }

    /// Pw turning about `axis` (normalised, through S) by the signed `angle` (rad):
    /// Pw(t) = Rot(axis, s(t)) Pw0.
    ///
    /// # Errors
    /// Non-finite inputs, a zero axis, or an invalid duration.
    pub fn about(
        start: Vector3,
        axis: &Vector3,
        angle: Real,
        duration: Real,
    ) -> Result<Self, ProfileError> {
        finite_vector(&start, "start position")?;
        let (axis, bell) = signed_motion(axis, angle, duration, ("angle", "axis"))?;
        Ok(Self { start, path: PositionPath::About { axis }, bell })
    }

    /// Pw along the semi-ellipse `arc` from its start to its end, the bell over its
    /// eccentric angle (0 to π).
    ///
    /// # Errors
    /// An invalid duration.
    pub fn arc(arc: SemiEllipse, duration: Real) -> Result<Self, ProfileError> {
        let bell = BellProfile::new(duration, PI)?;
        Ok(Self { start: arc.start(), path: PositionPath::Arc(arc), bell })
    }

    /// Pw at t = 0 (m, {b}).
    pub fn start(&self) -> Vector3 {
        self.start
    }

    /// The path.
    pub fn path(&self) -> PositionPath {
        self.path
    }

    /// The speed profile: distance in m for a line, rad for a rotation.
    pub fn bell(&self) -> &BellProfile {
        &self.bell
    }

    /// Pw at t = T (m, {b}).
    pub fn end(&self) -> Vector3 {
        self.sample(self.bell.duration()).0
    }

    /// Pw (m) and its velocity (m/s) at t (s), both in {b}; t is clamped to [0, T].
    pub fn sample(&self, t: Real) -> (Vector3, Vector3) {
        let (p, speed) = (self.at_distance(self.bell.progress(t)), self.bell.speed(t));
        match self.path {
            PositionPath::Hold => (p, Vector3::zeros()),
            PositionPath::Line { direction } => (p, direction * speed),
            PositionPath::About { axis } => (p, axis.cross(&p) * speed),
            PositionPath::Arc(arc) => (p, arc.tangent(self.bell.progress(t)) * speed),
        }
    }

    /// The distance along the path (unbounded, as [`Self::at_distance`]) of the path's point
    /// nearest to `p`: its projection on a line, its angle about the axis for a rotation, its
    /// eccentric angle on an arc (both in (-π, π]); 0 for a hold.
    pub fn nearest_distance(&self, p: &Vector3) -> Real {
        match self.path {
            PositionPath::Hold => 0.0,
            PositionPath::Line { direction } => (p - self.start).dot(&direction),
            PositionPath::About { axis } => {
                let (a, b) = (reject(&self.start, &axis), reject(p, &axis));
                axis.dot(&a.cross(&b)).atan2(a.dot(&b))
            }
            PositionPath::Arc(arc) => arc.nearest(p),
        }
    }

    /// Pw (m, {b}) at distance `s` along the path (m for a line, rad for a rotation), not
    /// limited to the bell's distance: a line goes on past its end.
    pub fn at_distance(&self, s: Real) -> Vector3 {
        match self.path {
            PositionPath::Hold => self.start,
            PositionPath::Line { direction } => self.start + direction * s,
            PositionPath::About { axis } => rotation_about(&axis, s) * self.start,
            PositionPath::Arc(arc) => arc.at(s),
        }
    }
}
