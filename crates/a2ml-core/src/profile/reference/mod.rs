//! Reference paths of the movement primitives: the value of one state variable and its time
//! derivative at any t, moving along the primitive's path with a bell speed (paper eq. 9).
//! One file per kind of value: [`position`] (Pw), [`rotation`] (Ow, Os), [`angle`] (θsw, θe);
//! this file holds the body frames the axes are read in and [`Reference`], which picks the
//! kind by the variable.

mod angle;
mod position;
mod rotation;

pub use angle::AngleReference;
pub use position::{PositionPath, PositionReference};
pub use rotation::{RotationPath, RotationReference};

use super::{BellProfile, ProfileError, SemiEllipse};
use crate::language::{Axis, BodyAxis, PathFeature, Target, ValueKind, Variable};
use crate::math::{Real, Rotation3, Vector3};

/// Directions shorter than this are treated as undefined.
const MIN_AXIS_NORM: Real = 1e-12;

/// The shoulder frame Os and the hand frame Ow at the start of a primitive, in {b}: where the
/// body axes r, l (Os columns 0, 1) and f, p (Ow columns 0, 1) are read (docs/design.md §2-4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyFrames {
    /// Os = [r, l, r × l].
    pub shoulder_frame: Rotation3,
    /// Ow = [f, p, f × p].
    pub ow: Rotation3,
}

impl BodyFrames {
    /// The unit body axis in {b}.
    pub fn axis(&self, axis: BodyAxis) -> Vector3 {
        let (frame, column) = match axis {
            BodyAxis::R => (&self.shoulder_frame, 0),
            BodyAxis::L => (&self.shoulder_frame, 1),
            BodyAxis::F => (&self.ow, 0),
            BodyAxis::P => (&self.ow, 1),
        };
        frame.matrix().column(column).into()
    }
}

/// The unit axis in {b} of a path feature: a fixed axis of {b} as given, or a body axis at
/// its value in `frames` (the start of the primitive), negated when its sign is negative.
///
/// # Errors
/// [`ProfileError::DegenerateAxis`] or [`ProfileError::NonFinite`] for an axis that cannot
/// be normalised.
pub fn resolve_axis(axis: &Axis, frames: &BodyFrames) -> Result<Vector3, ProfileError> {
    match *axis {
        Axis::Base(v) => unit(&v, "axis"),
        Axis::Body(body, sign) => {
            let v = frames.axis(body);
            unit(&if sign < 0.0 { -v } else { v }, "body axis")
        }
    }
}

fn unit(v: &Vector3, what: &'static str) -> Result<Vector3, ProfileError> {
    if !v.iter().all(|c| c.is_finite()) {
        return Err(ProfileError::NonFinite { what });
    }
    let norm = v.norm();
    if norm < MIN_AXIS_NORM {
        return Err(ProfileError::DegenerateAxis { what });
    }
    Ok(v / norm)
}

fn finite_vector(v: &Vector3, what: &'static str) -> Result<(), ProfileError> {
    if v.iter().all(|c| c.is_finite()) { Ok(()) } else { Err(ProfileError::NonFinite { what }) }
}

fn finite_rotation(r: &Rotation3, what: &'static str) -> Result<(), ProfileError> {
    if r.matrix().iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(ProfileError::NonFinite { what })
    }
}

fn finite_scalar(x: Real, what: &'static str) -> Result<(), ProfileError> {
    if x.is_finite() { Ok(()) } else { Err(ProfileError::NonFinite { what }) }
}

/// A motion along `direction` (a line's direction or a turn's axis) by the signed `size`, as
/// the unit direction the motion goes (turned round for a negative size) and the bell over
/// |size|, so that the travelled distance is never negative: the `line` and `about` of a
/// position and the `about` of a rotation. `size_name` and `direction_name` name the
/// values in an error.
///
/// # Errors
/// A non-finite size, a non-finite or zero direction, or an invalid duration.
fn signed_motion(
    direction: &Vector3,
    size: Real,
    duration: Real,
    (size_name, direction_name): (&'static str, &'static str),
) -> Result<(Vector3, BellProfile), ProfileError> {
    finite_scalar(size, size_name)?;
    let direction = unit(direction, direction_name)?;
    let direction = if size < 0.0 { -direction } else { direction };
    Ok((direction, BellProfile::new(duration, size.abs())?))
}

/// The reference of one state variable over a primitive, typed by the variable's kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reference {
    /// Pw.
    Position(PositionReference),
    /// Ow or Os.
    Rotation(RotationReference),
    /// θsw (periodic) or θe.
    Angle(AngleReference),
}

/// A reference's value and time derivative at one instant, in {b}.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sample {
    /// Pw.
    Position {
        /// Position (m).
        value: Vector3,
        /// Linear velocity (m/s).
        velocity: Vector3,
    },
    /// Ow or Os.
    Rotation {
        /// Rotation.
        value: Rotation3,
        /// Angular velocity (rad/s) in {b}.
        angular_velocity: Vector3,
    },
    /// θsw or θe.
    Angle {
        /// Angle (rad).
        value: Real,
        /// Rate (rad/s).
        rate: Real,
    },
}

impl Sample {
    /// The value alone.
    pub fn value(&self) -> Target {
        match *self {
            Sample::Position { value, .. } => Target::Position(value),
            Sample::Rotation { value, .. } => Target::Rotation(value),
            Sample::Angle { value, .. } => Target::Angle(value),
        }
    }
}

fn kind_of(value: &Target) -> ValueKind {
    match value {
        Target::Position(_) => ValueKind::Position,
        Target::Rotation(_) => ValueKind::Rotation,
        Target::Angle(_) => ValueKind::Angle,
    }
}

fn check_kind(variable: Variable, value: &Target) -> Result<(), ProfileError> {
    let (expected, found) = (variable.kind(), kind_of(value));
    if expected == found {
        Ok(())
    } else {
        Err(ProfileError::KindMismatch { variable, expected, found })
    }
}

impl Reference {
    /// The goal primitive MP^g(G, T) of `variable` from `start`: a straight line for Pw, the
    /// geodesic for Ow/Os, the shortest signed angle for θsw, the plain difference for θe.
    ///
    /// # Errors
    /// [`ProfileError::KindMismatch`] when `start` or `goal` is not of the variable's kind;
    /// non-finite values or an invalid duration.
    pub fn goal(
        variable: Variable,
        start: Target,
        goal: Target,
        duration: Real,
    ) -> Result<Self, ProfileError> {
        check_kind(variable, &start)?;
        check_kind(variable, &goal)?;
        Ok(match (start, goal) {
            (Target::Position(a), Target::Position(b)) => {
                Reference::Position(PositionReference::goal(a, b, duration)?)
            }
            (Target::Rotation(a), Target::Rotation(b)) => {
                Reference::Rotation(RotationReference::goal(a, b, duration)?)
            }
            (Target::Angle(a), Target::Angle(b)) => {
                Reference::Angle(AngleReference::goal(a, b, variable.wraps(), duration)?)
            }
            // check_kind made both kinds the variable's; kept total without a panic.
            _ => {
                let found = kind_of(&goal);
                return Err(ProfileError::KindMismatch {
                    variable,
                    expected: variable.kind(),
                    found,
                });
            }
        })
    }

    /// The path primitive MP^p(P, S, T) of `variable` from `start`: `line` (Pw), `about`
    /// (Pw about an axis through S, Ow, Os), `by` (θsw, θe) or `hold` (any). Body axes are
    /// read from `frames`, the frames at the start of the primitive.
    ///
    /// # Errors
    /// [`ProfileError::FeatureMismatch`] when the feature does not apply to the variable,
    /// [`ProfileError::MissingSize`] when its size is still open (Opt2 decides it),
    /// [`ProfileError::KindMismatch`], degenerate axes, non-finite values, invalid duration.
    pub fn path(
        variable: Variable,
        start: Target,
        feature: &PathFeature,
        frames: &BodyFrames,
        duration: Real,
    ) -> Result<Self, ProfileError> {
        check_kind(variable, &start)?;
        let keyword = match feature {
            PathFeature::Line { .. } => "line",
            PathFeature::About { .. } => "about",
            PathFeature::By { .. } => "by",
            PathFeature::Arc { .. } => "arc",
            PathFeature::Hold => "hold",
        };
        let missing = || ProfileError::MissingSize { variable, feature: keyword };
        Ok(match (*feature, start) {
            (PathFeature::Hold, _) => return Self::hold(variable, start, duration),
            (PathFeature::Line { direction, length }, Target::Position(p)) => {
                let length = length.ok_or_else(missing)?;
                Reference::Position(PositionReference::line(p, &direction, length, duration)?)
            }
            (PathFeature::About { axis, angle }, Target::Position(p)) => {
                let angle = angle.ok_or_else(missing)?;
                let axis = resolve_axis(&axis, frames)?;
                Reference::Position(PositionReference::about(p, &axis, angle, duration)?)
            }
            (PathFeature::About { axis, angle }, Target::Rotation(r)) => {
                let angle = angle.ok_or_else(missing)?;
                let axis = resolve_axis(&axis, frames)?;
                Reference::Rotation(RotationReference::about(r, &axis, angle, duration)?)
            }
            (PathFeature::Arc { through, to }, Target::Position(p)) => {
                let arc = SemiEllipse::through(p, to.ok_or_else(missing)?, through)?;
                Reference::Position(PositionReference::arc(arc, duration)?)
            }
            (PathFeature::By { angle }, Target::Angle(a)) => {
                Reference::Angle(AngleReference::by(a, angle, variable.wraps(), duration)?)
            }
            _ => return Err(ProfileError::FeatureMismatch { variable, feature: keyword }),
        })
    }

    /// `variable` kept at `start` for `duration` (s): the hold primitive (P = void, S = 0).
    ///
    /// # Errors
    /// [`ProfileError::KindMismatch`], a non-finite start or an invalid duration.
    pub fn hold(variable: Variable, start: Target, duration: Real) -> Result<Self, ProfileError> {
        check_kind(variable, &start)?;
        Ok(match start {
            Target::Position(p) => Reference::Position(PositionReference::hold(p, duration)?),
            Target::Rotation(r) => Reference::Rotation(RotationReference::hold(r, duration)?),
            Target::Angle(a) => {
                Reference::Angle(AngleReference::hold(a, variable.wraps(), duration)?)
            }
        })
    }

    /// The value and its time derivative at t (s), clamped to [0, T].
    pub fn sample(&self, t: Real) -> Sample {
        match self {
            Reference::Position(r) => {
                let (value, velocity) = r.sample(t);
                Sample::Position { value, velocity }
            }
            Reference::Rotation(r) => {
                let (value, angular_velocity) = r.sample(t);
                Sample::Rotation { value, angular_velocity }
            }
            Reference::Angle(r) => {
                let (value, rate) = r.sample(t);
                Sample::Angle { value, rate }
            }
        }
    }

    /// The speed profile: its duration is the primitive's T, its distance the path's length
    /// (m for Pw lines, rad otherwise).
    pub fn bell(&self) -> &BellProfile {
        match self {
            Reference::Position(r) => r.bell(),
            Reference::Rotation(r) => r.bell(),
            Reference::Angle(r) => r.bell(),
        }
    }

    /// The duration T (s).
    pub fn duration(&self) -> Real {
        self.bell().duration()
    }

    /// The value at t = 0.
    pub fn start(&self) -> Target {
        match self {
            Reference::Position(r) => Target::Position(r.start()),
            Reference::Rotation(r) => Target::Rotation(r.start()),
            Reference::Angle(r) => Target::Angle(r.start()),
        }
    }

    /// The value at t = T: where the next segment of this variable starts.
    pub fn end(&self) -> Target {
        self.sample(self.duration()).value()
    }

    /// The fraction of the path's distance (unbounded, as [`Self::at_fraction`]) at which the
    /// path comes nearest to `value`; `None` for a path that does not move (a hold, or a
    /// distance of 0) or a value of another kind.
    pub fn nearest_fraction(&self, value: &Target) -> Option<Real> {
        let distance = self.bell().distance();
        if distance <= 0.0 {
            return None;
        }
        let s = match (self, value) {
            (Reference::Position(r), Target::Position(p)) => r.nearest_distance(p),
            (Reference::Rotation(r), Target::Rotation(q)) => r.nearest_distance(q),
            (Reference::Angle(r), Target::Angle(a)) => r.nearest_distance(*a),
            _ => return None,
        };
        Some(s / distance)
    }

    /// The value at `fraction` of the path's distance: 0 at the start, 1 at the end, and beyond
    /// 1 further along the same path (a line past its end, a rotation further round).
    pub fn at_fraction(&self, fraction: Real) -> Target {
        let s = fraction * self.bell().distance();
        match self {
            Reference::Position(r) => Target::Position(r.at_distance(s)),
            Reference::Rotation(r) => Target::Rotation(r.at_distance(s)),
            Reference::Angle(r) => Target::Angle(r.at_distance(s)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{PI, rotation_about, rotation_distance};

    /// The rotation about `axis` (normalised here) by `angle`, for the kinds' tests too.
    pub(super) fn rot(axis: Vector3, angle: Real) -> Rotation3 {
        Rotation3::from_matrix_unchecked(rotation_about(&axis.normalize(), angle))
    }

    #[test]
    fn body_axes_come_from_the_start_frames() {
        let frames = BodyFrames {
            shoulder_frame: rot(Vector3::new(1.0, 2.0, 3.0), 0.4),
            ow: rot(Vector3::new(-1.0, 0.5, 0.2), 1.3),
        };
        let col = |r: &Rotation3, i: usize| -> Vector3 { r.matrix().column(i).into() };
        let cases = [
            (BodyAxis::R, col(&frames.shoulder_frame, 0)),
            (BodyAxis::L, col(&frames.shoulder_frame, 1)),
            (BodyAxis::F, col(&frames.ow, 0)),
            (BodyAxis::P, col(&frames.ow, 1)),
        ];
        for (body, expected) in cases {
            let plus = resolve_axis(&Axis::Body(body, 1.0), &frames).expect("unit");
            let minus = resolve_axis(&Axis::Body(body, -1.0), &frames).expect("unit");
            assert!((plus - expected).norm() < 1e-15);
            assert!((minus + expected).norm() < 1e-15);
        }
        assert!(matches!(
            resolve_axis(&Axis::Base(Vector3::zeros()), &frames),
            Err(ProfileError::DegenerateAxis { .. })
        ));
    }

    #[test]
    fn coincident_goals_hold() {
        let p = Vector3::new(0.1, 0.2, 0.3);
        let r = Reference::goal(Variable::Pw, Target::Position(p), Target::Position(p), 1.0)
            .expect("valid");
        assert!(matches!(r, Reference::Position(ref x) if x.path() == PositionPath::Hold));
        let o = rot(Vector3::z(), 0.3);
        let r = Reference::goal(Variable::Ow, Target::Rotation(o), Target::Rotation(o), 1.0)
            .expect("valid");
        assert!(matches!(r, Reference::Rotation(ref x) if x.path() == RotationPath::Hold));
        match r.sample(0.5) {
            Sample::Rotation { value, angular_velocity } => {
                assert_eq!(value, o);
                assert_eq!(angular_velocity, Vector3::zeros());
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn mismatches_are_errors() {
        let frames =
            BodyFrames { shoulder_frame: Rotation3::identity(), ow: Rotation3::identity() };
        let line = PathFeature::Line { direction: Vector3::x(), length: Some(0.1) };
        assert!(matches!(
            Reference::path(
                Variable::Ow,
                Target::Rotation(Rotation3::identity()),
                &line,
                &frames,
                1.0
            ),
            Err(ProfileError::FeatureMismatch { variable: Variable::Ow, feature: "line" })
        ));
        assert!(matches!(
            Reference::goal(Variable::Pw, Target::Angle(0.0), Target::Angle(1.0), 1.0),
            Err(ProfileError::KindMismatch { variable: Variable::Pw, .. })
        ));
        let open = PathFeature::Line { direction: Vector3::x(), length: None };
        assert!(matches!(
            Reference::path(Variable::Pw, Target::Position(Vector3::x()), &open, &frames, 1.0),
            Err(ProfileError::MissingSize { feature: "line", .. })
        ));
        assert!(matches!(
            Reference::goal(
                Variable::Pw,
                Target::Position(Vector3::x()),
                Target::Position(Vector3::new(Real::NAN, 0.0, 0.0)),
                1.0
            ),
            Err(ProfileError::NonFinite { .. })
        ));
        assert!(matches!(
            Reference::hold(Variable::Elbow, Target::Angle(1.0), -1.0),
            Err(ProfileError::InvalidDuration { .. })
        ));
    }

    #[test]
    fn negative_sizes_reverse_the_direction() {
        let p0 = Vector3::new(0.3, 0.0, -0.2);
        let r = PositionReference::line(p0, &Vector3::y(), -0.1, 1.0).expect("valid");
        assert!((r.end() - (p0 - 0.1 * Vector3::y())).norm() < 1e-15);
        let r = RotationReference::about(Rotation3::identity(), &Vector3::z(), -0.5, 1.0)
            .expect("valid");
        assert!(rotation_distance(&r.end(), &rot(Vector3::z(), -0.5)) < 1e-15);
    }

    #[test]
    fn at_fraction_follows_the_path_and_goes_on_past_its_end() {
        let p0 = Vector3::new(0.3, 0.0, -0.2);
        let line = Reference::Position(
            PositionReference::line(p0, &Vector3::z(), 0.2, 1.0).expect("valid"),
        );
        // Halfway in distance is not halfway in time (the bell is slow at the ends), but at
        // the midpoint of the symmetric bell both agree; the ends agree always.
        assert_eq!(line.at_fraction(0.0), line.start());
        assert_eq!(line.at_fraction(1.0), line.end());
        assert_eq!(line.at_fraction(0.5), line.sample(0.5).value());
        match line.at_fraction(1.5) {
            Target::Position(p) => assert!((p - (p0 + 0.3 * Vector3::z())).norm() < 1e-15),
            other => panic!("{other:?}"),
        }
        let turn = Reference::Rotation(
            RotationReference::about(Rotation3::identity(), &Vector3::x(), 0.4, 1.0)
                .expect("valid"),
        );
        match turn.at_fraction(2.0) {
            Target::Rotation(r) => assert!(rotation_distance(&r, &rot(Vector3::x(), 0.8)) < 1e-15),
            other => panic!("{other:?}"),
        }
        let swivel = Reference::Angle(AngleReference::by(3.0, 0.2, true, 1.0).expect("valid"));
        // Periodic angles wrap into (-π, π].
        match swivel.at_fraction(1.0) {
            Target::Angle(a) => assert!((a - (3.2 - 2.0 * PI)).abs() < 1e-15),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn nearest_fraction_finds_the_fraction_of_a_point_on_the_path() {
        let p0 = Vector3::new(0.3, -0.1, -0.2);
        let axis = Vector3::new(0.2, -0.4, 0.9).normalize();
        let r0 = rot(Vector3::new(0.5, 0.1, -0.3), 0.8);
        let references = [
            Reference::Position(PositionReference::line(p0, &axis, 0.2, 1.0).expect("valid")),
            Reference::Position(PositionReference::about(p0, &axis, -1.1, 1.0).expect("valid")),
            Reference::Rotation(RotationReference::about(r0, &axis, 1.3, 1.0).expect("valid")),
            Reference::Angle(AngleReference::by(2.9, 0.6, true, 1.0).expect("valid")),
            Reference::Angle(AngleReference::by(1.0, -0.7, false, 1.0).expect("valid")),
        ];
        for (i, r) in references.iter().enumerate() {
            for f in [0.0, 0.3, 1.0, 1.4] {
                let found = r.nearest_fraction(&r.at_fraction(f)).expect("a moving path");
                assert!((found - f).abs() < 1e-12, "reference {i}: {found} for {f}");
            }
        }
        // Off the line: the projection.
        let line = &references[0];
        let off = Target::Position(p0 + axis * 0.1 + axis.cross(&Vector3::x()).normalize() * 0.05);
        assert!((line.nearest_fraction(&off).expect("moving") - 0.5).abs() < 1e-12);
        let hold = Reference::hold(Variable::Pw, Target::Position(p0), 1.0).expect("valid");
        assert_eq!(hold.nearest_fraction(&Target::Position(p0)), None);
    }
}
